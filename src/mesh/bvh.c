/*
 * bvh.c -- a bounding-volume hierarchy over triangles and the nearest
 * triangle of a point, bit-identical to a loop over every triangle.
 *
 * The rule that makes the search equal the loop.  The loop keeps the
 * smallest rounded distance hd__tri_nearest returns and, among the
 * triangles at that distance, the smallest index.  The search keeps the
 * same pair (d*, index) over the triangles it evaluates and a threshold
 * thr, a proven upper bound on next(d*)^2 for the final d* (next(d) is the
 * double after d): each kernel call lowers it to next(d)^2 rounded up,
 * and each rigorous upper bound hi2 on a triangle's squared distance to
 * thr_from_hi(hi2).  It skips a triangle, or every triangle under a node,
 * only when a lower bound L2 on its exact squared distance proves
 * L2 > thr: then its true distance t > next(d*), and rounding being
 * monotone, round(t) >= next(d*) > d*, so the skipped triangle could
 * neither beat the answer nor tie it (a tie would need its index
 * compared).  As thr only decreases, a triangle skipped once stays
 * skippable.  So the search ends with the loop's pair, whatever the order
 * of visits, the seed, the group or the thread.
 *
 * The bounds are computed in doubles and moved outward by more than their
 * accumulated rounding error (proofs at each function); where underflow
 * could add an absolute error they give no information.  Coordinates are
 * at most 2^511 in magnitude (the library checks 1e153), so no
 * intermediate overflows: a difference is below 2^512 ... within DBL_MAX
 * for the checked inputs (|difference| < 2.1e153, 3 * 2.1e153^2 <
 * 1.4e307).
 *
 * The tree: nodes split at the median of the triangles' centroids along
 * the longest axis of their box, down to leaves of at most LEAF
 * triangles; each node's box is the exact minimum and maximum of its
 * corners (no rounding), each triangle prepared once (hd__tri_prep).  A
 * query starts from a seed triangle (the previous query's nearest); near
 * its seed it searches the seed's leaf and then its ancestors' siblings
 * (climb), else it descends from the root; either way nearest child first, discarding nodes by their boxes, or where
 * a node has a frame (hd__bvh_frames: nearly orthonormal axes, the first
 * along the node's normal, and the slabs holding its triangles), by the
 * distance to the frame's slabs, much tighter on a nearly flat patch seen
 * at an angle (frame_lo2).  A leaf's
 * triangles pass three stages, each in increasing order of its lower
 * bound and each stopping at the first bound above thr: the cheap bounds
 * (the triangle's box, then the support bound in the direction of its
 * box's centre), the prepared bounds (hd__tri_bounds_prep: lo2 discards,
 * hi2 lowers thr) as soon as the leaf is screened, and the kernel, on
 * the candidates left at the end.  Triangles that share the best one's
 * nearest corner and certainly have it as theirs are decided without the
 * kernel (corner_tie).  hd__bvh_collect and hd__bvh_nearest_in let a
 * group of neighbouring points share one list of triangles.
 */
#include "mesh/mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

/* The shrink factor of every bound: exceeds (1 + 2^-53)^16 - 1. */
#define SHRINK (1.0 - 0x1p-48)
/* Below this a computed square or quotient may carry underflow's absolute
 * error (at most 2^-1074 an operation): bounds there are taken as 0. */
#define TINY 0x1p-1000
#define MAX_DEPTH 128
#if defined(__GNUC__)
#define NOINLINE __attribute__((noinline)) /* a rare path kept out of a hot loop */
#else
#define NOINLINE
#endif

/* ---- lower bounds ------------------------------------------------------- */

/* hd__box_lb2s(b, p[0], p[1], p[2]), bit for bit: the same operations in
 * the same order, x and y in one SSE2 register where there is one (its
 * maximum is u > v ? u : v, as the scalar one, zeros and NaN included),
 * and (gx^2 + gy^2) + gz^2.  The descent's and the screens' box tests
 * (c2m_bench's near and far rows measure it). */
HD__INLINE double box_lb2s(const hd__box_t *b, const double *p) {
#if defined(__SSE2__)
    __m128d q = _mm_loadu_pd(p), lo = _mm_loadu_pd(b->lo), hi = _mm_loadu_pd(b->hi);
    __m128d g = _mm_max_pd(_mm_sub_pd(lo, q), _mm_sub_pd(q, hi));
    g = _mm_max_pd(g, _mm_setzero_pd());
    g = _mm_mul_pd(g, g);
    double u = b->lo[2] - p[2], v = p[2] - b->hi[2], gz = u > v ? u : v;
    gz = gz > 0 ? gz : 0;
    return (_mm_cvtsd_f64(g) + _mm_cvtsd_f64(_mm_unpackhi_pd(g, g))) + gz * gz;
#else
    return hd__box_lb2s(b, p[0], p[1], p[2]);
#endif
}

/* Box: the gap g on each axis is a difference of doubles rounded once
 * (relative error <= u = 2^-53, and exact when it is not normal), its
 * square adds one rounding, the two sums two more, the square root half a
 * unit and one more rounding: the computed sqrt(s) is at most the true
 * distance times (1 + u)^5.5 when s >= TINY (underflow could only add
 * 2^-1072 to s, a relative 2^-72).  The final product rounds once more.
 * (1 + u)^6.5 * SHRINK < 1, so the result never exceeds the true
 * distance from p to the box. */
double hd__box_lower(const hd__box_t *b, const double p[3]) {
    double s = box_lb2s(b, p);
    if (!(s >= TINY)) return 0.0;
    return sqrt(s) * SHRINK;
}

/* The same test without the square root: whether the box is certainly
 * farther than a distance whose square is at most thr2 (below).  The
 * computed s is at most the true squared distance times (1 + u)^5 when
 * s >= TINY, and s * SHRINK, rounded, is below s / (1 + u)^5: so
 * s * SHRINK > thr2 >= next^2 proves the box farther than next (and when
 * s < TINY, s * SHRINK < thr2 as thr2 >= 2^-990). */
static int box_beyond(double s, double thr2) { return s * SHRINK > thr2; }

/* An upper bound on next^2, at least 2^-990: the product rounds once
 * (relative u when normal), the factor covers it; below 2^-990 the floor
 * stands in for it. */
static double square_up(double next) {
    double t = next * next * (1.0 + 0x1p-48);
    return t > 0x1p-990 ? t : 0x1p-990;
}

/* Support bound: for any vector w, every point x of the triangle (a convex
 * combination of its corners) has w.(p - x) >= min over corners k of
 * w.(p - v_k), so |p - x| >= that minimum / |w| (Cauchy-Schwarz).  With w
 * the direction from a rough closest point to p the bound is nearly the
 * distance; any w is valid, so w need not be exact.
 *
 * Rounding, for the w actually stored (scaled by a power of two to a
 * largest component in [1/2, 1) when it is below 2^-500, so that |w|^2 >=
 * 2^-1000 in every case, and |w|^2 < 1.3e307 as p and q lie within the
 * checked range): each difference y = p - v_k
 * is rounded once (|y - (p - v_k)| <= u |p - v_k|), the dot product
 * s = w.y adds at most gamma_3 = 3u/(1 - 3u) of A = sum |w_i y_i| (plus
 * 3 * 2^-1074 of underflow), so |s - w.(p - v_k)| <= 4.01u A + 2^-1072;
 * the computed A is within (1 + u)^3 of the true one, and e = 2^-50 A +
 * 2^-1020 exceeds the error.  So m = min(s_k - e_k), rounded once
 * (relative u), is at most the true minimum times (1 + u) when positive.
 * |w|^2 >= 2^-1000 is computed with relative error <= 3u (underflowed
 * squares add at most 3 * 2^-1074, a relative 2^-72), its root within (1 + u)^2.5 of |w|, and the
 * quotient rounds once: m / |w| computed is at most the true bound times
 * (1 + u)^5; the product by SHRINK rounds once more.  Quotients below TINY
 * are taken as 0. */
/* The support bound for direction w over the corners of the n triangles
 * t[0 .. n): min over corners of w.(p - v) / |w|, shrunk (the proof
 * above); 0 when w is zero, not finite, or the bound is not positive. */
double hd__support_lower(const hd__tri_t *t, size_t n, const double p[3], double *w) {
    double big = fabs(w[0]) > fabs(w[1]) ? fabs(w[0]) : fabs(w[1]);
    big = fabs(w[2]) > big ? fabs(w[2]) : big;
    if (!(big > 0) || !isfinite(big)) return 0.0;
    if (big < 0x1p-500) { /* only then can |w|^2 underflow: scale it up */
        int e;
        frexp(big, &e);
        for (int i = 0; i < 3; i++) w[i] = ldexp(w[i], -e);
    }
    double m = INFINITY;
    for (size_t j = 0; j < n; j++)
        for (int k = 0; k < 3; k++) {
            const double *v = t[j].v[k];
            double y0 = p[0] - v[0], y1 = p[1] - v[1], y2 = p[2] - v[2];
            double s = w[0] * y0 + w[1] * y1 + w[2] * y2;
            double A = fabs(w[0] * y0) + fabs(w[1] * y1) + fabs(w[2] * y2);
            double e = s - (0x1p-50 * A + 0x1p-1020);
            m = e < m ? e : m;
        }
    if (!(m > 0)) return 0.0;
    double r = m / sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    return r >= TINY ? r * SHRINK : 0.0;
}


/* ---- the frames --------------------------------------------------------- */

#define FRAME_MAX 64 /* triangles of the largest node given a frame */

/* a x b */
static void cross3(const double *a, const double *b, double *o) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static int unit3(double *a) {
    double l = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    if (!(l > 0) || !isfinite(l)) return 0;
    for (int i = 0; i < 3; i++) a[i] /= l;
    return 1;
}

/* The axes of a frame: the unit normal n, and n x e_k (e_k the axis
 * along which n is smallest) and n x that, normalised.  Only their near
 * orthonormality is used, and it is checked on the computed doubles: each
 * |a_j|^2 and a_j . a_k is a sum of three products, within 3.01u of the
 * product of the norms (about 1) of its true value, so computed values
 * within 2^-45 of 1 and of 0 put the true ones within 2^-44 (eta and c in
 * frame_lo2's proof), and an L1 norm computed below 1.79 is below 1.8. */
static int frame_axes(const double *normal, double a[3][3]) {
    memcpy(a[0], normal, sizeof a[0]);
    if (!unit3(a[0])) return 0;
    int k = 0;
    for (int i = 1; i < 3; i++)
        if (fabs(a[0][i]) < fabs(a[0][k])) k = i;
    double e[3] = {0, 0, 0};
    e[k] = 1;
    cross3(a[0], e, a[1]);
    if (!unit3(a[1])) return 0;
    cross3(a[0], a[1], a[2]);
    if (!unit3(a[2])) return 0;
    for (int j = 0; j < 3; j++) {
        if (!(fabs(a[j][0]) + fabs(a[j][1]) + fabs(a[j][2]) < 1.79)) return 0;
        for (int m = j; m < 3; m++) {
            double d = a[j][0] * a[m][0] + a[j][1] * a[m][1] + a[j][2] * a[m][2];
            if (!(fabs(d - (j == m)) <= 0x1p-45)) return 0;
        }
    }
    return 1;
}

/* The frame of triangles tris[0 .. n).  The slabs: for a corner v, the
 * computed a_j . v is within gamma_3 |a_j|_1 |v|_inf + 3 * 2^-1074 <=
 * 5.5u V + 2^-1072 of the true one (V the largest corner coordinate's
 * magnitude, |a_j|_1 <= 1.8), and adding or subtracting
 * E = 2^-48 V + 2^-1000 (32u V, rounded once) covers that error and the
 * rounding of the sum itself (u of at most 1.81 V + E): so [lo_j, hi_j]
 * holds every corner's exact a_j . v, and as a slab is convex, every point
 * of the triangles. */
static void frame_of(const hd__tri_t *tris, size_t n, hd__bvh_frame_t *f) {
    double normal[3] = {0, 0, 0}, V = 0;
    for (size_t i = 0; i < n; i++) {
        const hd__tri_t *t = &tris[i];
        double e1[3], e2[3], c[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = t->v[1][k] - t->v[0][k], e2[k] = t->v[2][k] - t->v[0][k];
            for (int j = 0; j < 3; j++) V = fabs(t->v[j][k]) > V ? fabs(t->v[j][k]) : V;
        }
        cross3(e1, e2, c);
        for (int k = 0; k < 3; k++) normal[k] += c[k];
    }
    f->ok = frame_axes(normal, f->a);
    if (!f->ok) return;
    double E = 0x1p-48 * V + 0x1p-1000;
    for (int j = 0; j < 3; j++) {
        double lo = INFINITY, hi = -INFINITY;
        for (size_t i = 0; i < n; i++)
            for (int k = 0; k < 3; k++) {
                const double *v = tris[i].v[k];
                double d = f->a[j][0] * v[0] + f->a[j][1] * v[1] + f->a[j][2] * v[2];
                lo = d < lo ? d : lo, hi = d > hi ? d : hi;
            }
        f->lo[j] = lo - E, f->hi[j] = hi + E;
    }
}

/* Make the frame of node k, holding tris[first, first + n), unless another
 * thread does: the thread that moves its state from 0 to 1 makes it and
 * publishes it with state 2 (a frame) or 3 (none), release; readers
 * acquire; one that finds it being made uses the box meanwhile.  Returns
 * the state seen last. */
static NOINLINE int frame_make(const hd__bvh_t *t, uint32_t k, uint32_t first, uint32_t n) {
    hd__bvh_frame_t *f = &t->frames[k];
    int st = 0;
    if (!atomic_compare_exchange_strong_explicit(&f->state, &st, 1, memory_order_acquire, memory_order_acquire))
        return st;
    frame_of(t->tris + first, n, f);
    st = f->ok ? 2 : 3;
    atomic_store_explicit(&f->state, st, memory_order_release);
    return st;
}

/* The frame of node k (of at most FRAME_MAX triangles), made if need be;
 * NULL when there is none (yet). */
static inline const hd__bvh_frame_t *frame_get(const hd__bvh_t *t, uint32_t k, uint32_t first, uint32_t n) {
    const hd__bvh_frame_t *f = &t->frames[k];
    int st = atomic_load_explicit(&f->state, memory_order_acquire);
    if (st == 2) return f;
    if (st == 0 && frame_make(t, k, first, n) == 2) return f;
    return NULL;
}

/* H: a frame's axes have |a_j|_1 <= 1.8, so a computed a_j . v is at
 * most 1.8 V (1 + 4u) + 2^-1072 in magnitude for the largest coordinate
 * magnitude V of the corners (the root box's), and its slabs add
 * E = 2^-48 V + 2^-1000 and one rounding: 2 V + 2^-990 bounds every
 * |lo_j| and |hi_j|, and the factor 1 + 2^-50 covers the rounding of that
 * sum and of itself. */
int hd__bvh_frames(hd__bvh_t *t) {
    free(t->frames);
    t->frame_h = t->frame_reach2 = 0;
    t->frames = hd__calloc_array(t->n_nodes, sizeof *t->frames);
    if (!t->frames) return HD_ENOMEM;
    /* every state 0 as the zeroed memory is (an atomic_int is a lock-free
     * int on every target of the library): a near cloud writes no frame */
    const hd__box_t *r = &t->nodes[0].box;
    for (int k = 0; k < 3; k++) {
        double m = fabs(r->lo[k]) > fabs(r->hi[k]) ? fabs(r->lo[k]) : fabs(r->hi[k]);
        t->frame_h = m > t->frame_h ? m : t->frame_h;
    }
    t->frame_h = (2 * t->frame_h + 0x1p-990) * (1 + 0x1p-50);
    /* the mean squared diagonal of the largest framed nodes */
    struct { uint32_t node, n; } stack[MAX_DEPTH];
    int top = 0;
    size_t roots = 0;
    stack[top].node = 0, stack[top++].n = (uint32_t)t->n_tris;
    while (top > 0) {
        uint32_t me = stack[--top].node, n = stack[top].n;
        const hd__bvh_node_t *node = &t->nodes[me];
        if (n <= FRAME_MAX) {
            const hd__box_t *b = &node->box;
            double x = b->hi[0] - b->lo[0], y = b->hi[1] - b->lo[1], z = b->hi[2] - b->lo[2];
            t->frame_reach2 += x * x + y * y + z * z;
            roots++;
            continue;
        }
        stack[top].node = me + 1, stack[top++].n = n / 2;
        stack[top].node = node->first_or_second, stack[top++].n = n - n / 2;
    }
    t->frame_reach2 /= (double)roots;
    return HD_OK;
}

/* ---- the query ---------------------------------------------------------- */

/* An upper bound on next(d*)^2 from an upper bound h2 on the exact squared
 * distance t*^2 of some triangle, for the final d* = round(t*) of the
 * search: t* <= sqrt(h2), so d* <= round(sqrt(h2)) <= sqrt(h2) (1 + u),
 * next(d*) <= d* (1 + 2u) when normal, and next(d*)^2 <= h2 (1 + 3.1 u)^2
 * < h2 (1 + 2^-50); the computed h2 (1 + 2^-48) rounds down by at most a
 * relative u and stays above that.  When next(d*) is below 2^-495 (d*
 * subnormal included) the floor 2^-990 is above its square. */
static double thr_from_hi(double h2) {
    double t = h2 * (1.0 + 0x1p-48);
    return t > 0x1p-990 ? t : 0x1p-990;
}

/* A candidate: a triangle (its position) with a lower bound lo2 on its
 * squared distance that did not discard it.  Two stages: the cheap
 * bounds (the triangle's box and support bound) give a first lo2, and the
 * triangles are then taken in increasing lo2 for the prepared bounds
 * (hd__tri_bounds_prep), whose lo2 orders the kernel calls in turn; each
 * stage stops at the first lo2 above the threshold, which every hi2 and
 * every kernel call may lower.  A candidate left has lo2 > thr >=
 * next(d*)^2: the file's rule discards it. */
typedef struct {
    double lo2;
    size_t pos;
} cand_t;

#define CANDS 64

typedef struct {
    hd__tri_near_t best;
    size_t index, pos;
    /* thr >= next(d*)^2 for the answer d* (at least 2^-990): the least of
     * square_up(next(best.d)) and thr_from_hi of every hi2 computed */
    double thr;
    size_t n_cheap, n_prep;
    cand_t cheap[CANDS], prep[CANDS];
} search_t;

/* The double after d, for a distance (finite, d >= +0): its bits plus one,
 * as nextafter(d, INFINITY) gives, without the call (a -0 would give -2^-1074,
 * which square_up takes to its floor, as it takes nextafter's 2^-1074). */
static inline double next_up(double d) { return hd__double_of(hd__bits_of(d) + 1); }

static void evaluate(const hd__bvh_t *t, const double *p, size_t pos, search_t *s, hd__bvh_stats_t *st) {
    const hd__tri_t *tr = &t->tris[pos];
    hd__tri_near_t r;
    hd__tri_nearest(p, tr->v[0], tr->v[1], tr->v[2], &r); /* inputs checked: cannot fail */
    st->kernel++;
    st->exact += (uint64_t)r.exact;
    if (s->pos == SIZE_MAX || r.d < s->best.d || (r.d == s->best.d && tr->index < s->index)) {
        s->best = r;
        s->index = tr->index;
        s->pos = pos;
        double t2 = square_up(next_up(r.d));
        s->thr = t2 < s->thr ? t2 : s->thr;
    }
}

static void sort_cands(cand_t *c, size_t n) {
    for (size_t i = 1; i < n; i++) { /* insertion sort: the lists are short */
        cand_t x = c[i];
        size_t j = i;
        for (; j > 0 && c[j - 1].lo2 > x.lo2; j--) c[j] = c[j - 1];
        c[j] = x;
    }
}

/* A tie at a shared corner without the kernel.  When the best triangle's
 * nearest feature is a corner V and triangle k has a corner X bit-equal to
 * V with p certainly in X's region of k (XY . XP < 0 and XZ . XP < 0,
 * each with its rounding error bound: bounds.c's corner test, 6u of the
 * products' magnitudes plus 2^-700, for coordinates below 2^100), then for
 * every x of k, |p - x|^2 = |p - X|^2 + |x - X|^2 - 2 (x - X) . (p - X)
 * >= |p - X|^2: k's true distance is |p - V|, the best one's, so the
 * kernel would round it alike, and it returns the corner as the closest
 * point with weight 1 (tri.c's and exact.c's corner cases).  So k is
 * decided here: it wins exactly when its index is smaller.  1 when
 * decided. */
static int corner_tie(const hd__bvh_t *t, const double *p, size_t k, search_t *s) {
    const hd__tri_prep_t *q = hd__bvh_prep(t, k);
    if (s->best.feature < HD__TRI_VERTEX_A || !q->direct) return 0;
    if (!(fabs(p[0]) < 0x1p100 && fabs(p[1]) < 0x1p100 && fabs(p[2]) < 0x1p100)) return 0;
    const double *corner[3] = {q->a, q->b, q->c};
    int x = 0;
    while (x < 3 && memcmp(corner[x], s->best.point, sizeof q->a) != 0) x++;
    if (x == 3) return 0;
    /* the two edges from X, rounded as the prepared ones are */
    double e[2][3];
    for (int i = 0; i < 3; i++) {
        double ab = q->ab[i], ac = q->ac[i], bc = q->bc[i];
        e[0][i] = x == 0 ? ab : x == 1 ? -ab : -ac;
        e[1][i] = x == 0 ? ac : x == 1 ? bc : -bc;
    }
    const double *X = corner[x];
    double xp[3] = {p[0] - X[0], p[1] - X[1], p[2] - X[2]};
    for (int j = 0; j < 2; j++) {
        double dot = e[j][0] * xp[0] + e[j][1] * xp[1] + e[j][2] * xp[2];
        double mag = fabs(e[j][0] * xp[0]) + fabs(e[j][1] * xp[1]) + fabs(e[j][2] * xp[2]);
        if (!(dot + (6 * 0x1p-53 * mag + 0x1p-700) < 0)) return 0;
    }
    size_t index = t->tris[k].index;
    if (index < s->index) {
        s->index = index;
        s->pos = k;
        s->best.feature = (hd__tri_feature_t)(HD__TRI_VERTEX_A + x);
        s->best.exact = 0;
        for (int i = 0; i < 3; i++) s->best.bary[i] = i == x;
    }
    return 1;
}

/* The kernel for the prepared stage's candidates; the list is emptied. */
static void flush_prep(const hd__bvh_t *t, const double *p, search_t *s, hd__bvh_stats_t *st) {
    sort_cands(s->prep, s->n_prep);
    for (size_t i = 0; i < s->n_prep && s->prep[i].lo2 <= s->thr; i++) {
        size_t k = s->prep[i].pos;
        if (s->pos != SIZE_MAX && corner_tie(t, p, k, s)) st->ties++;
        else evaluate(t, p, k, s, st);
    }
    s->n_prep = 0;
}

/* Triangle k's prepared bounds: discarded when lo2 > thr, else a
 * candidate of the kernel, and its hi2 may lower thr. */
HD__INLINE void consider(const hd__bvh_t *t, const double *p, size_t k, search_t *s, hd__bvh_stats_t *st) {
    double lo2, hi2;
    st->bounded++;
    hd__tri_bounds_below(p, hd__bvh_prep(t, k), s->thr, &lo2, &hi2);
    if (lo2 > s->thr) return;
    double h = thr_from_hi(hi2);
    s->thr = h < s->thr ? h : s->thr;
    if (s->n_prep == CANDS) flush_prep(t, p, s, st);
    s->prep[s->n_prep++] = (cand_t){lo2, k};
}

static void flush_cheap(const hd__bvh_t *t, const double *p, search_t *s, hd__bvh_stats_t *st) {
    sort_cands(s->cheap, s->n_cheap);
    for (size_t i = 0; i < s->n_cheap && s->cheap[i].lo2 <= s->thr; i++) {
        size_t k = s->cheap[i].pos;
        if (s->pos != SIZE_MAX && corner_tie(t, p, k, s)) st->ties++;
        else consider(t, p, k, s, st);
    }
    s->n_cheap = 0;
}

/* The support bound of triangle t as a test: whether every point x of it
 * is proven farther than sqrt(thr) from p.  With w the computed p - c (c
 * any point, here the centre of the triangle's box) and x_k = v_k - c,
 * w . (p - x) >= w . (p - c) - max_k w . x_k for x in the hull, and
 * |p - x| >= w . (p - x) / |w|, so num^2 > thr |w|^2 with num below
 * w . (p - c) - max_k w . x_k proves it; no square root, no quotient.
 *
 * Rounding: each w_i is p_i - c_i rounded once, so w . (p - c) >= W2
 * (1 - 1.01u) for the true W2 = |w|^2, and the computed W2c is within
 * 3.01u of it (W2c >= 2^-900: underflow adds a relative 2^-170 at most);
 * x_k rounded once per component and the dot product give w . x_k below
 * s_k + 4.1u A_k (A_k = sum |w_i x_ki| computed), and m_k = s_k +
 * 2^-49 A_k + 2^-1000, computed, is above it (the extra 8u A_k covers the
 * sum's rounding, 2^-1000 underflow).  X = W2c (1 - 2^-50) rounds to below
 * W2 (1 - 4.1u); (X - max m_k) (1 - 2^-50) rounds to below the difference
 * when positive: num.  num^2 (1 - 2^-50) rounds to below num^2, and
 * thr W2c (1 + 2^-49) to above thr W2 when it is at least 2^-1000 (then
 * thr W2c was rounded as a normal number). */
static int support_beyond(const hd__tri_t *t, const double *c, const double *p, double thr) {
    double w[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
    double W2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    if (!(W2 >= 0x1p-900)) return 0;
    double M = -INFINITY;
    for (int k = 0; k < 3; k++) {
        const double *v = t->v[k];
        double x0 = v[0] - c[0], x1 = v[1] - c[1], x2 = v[2] - c[2];
        double sk = w[0] * x0 + w[1] * x1 + w[2] * x2;
        double Ak = fabs(w[0] * x0) + fabs(w[1] * x1) + fabs(w[2] * x2);
        double mk = sk + (0x1p-49 * Ak + 0x1p-1000);
        M = mk > M ? mk : M;
    }
    double num = (W2 * (1 - 0x1p-50) - M) * (1 - 0x1p-50);
    if (!(num > 0)) return 0;
    double rhs = thr * W2 * (1 + 0x1p-49);
    return rhs >= 0x1p-1000 && num * num * (1 - 0x1p-50) > rhs;
}

/* Triangle k's cheap bounds: its box's (hd__box_lb2s shrunk, below d^2
 * by box_beyond's proof) and the support bound; a triangle left is a
 * candidate of the prepared stage with the box's bound as its key. */
HD__INLINE void screen(const hd__bvh_t *t, const double *p, size_t k, search_t *s, hd__bvh_stats_t *st) {
    const hd__box_t *bx = &t->boxes[k];
    double b = box_lb2s(bx, p);
    if (box_beyond(b, s->thr)) return;
    double c[3] = {bx->lo[0] / 2 + bx->hi[0] / 2, bx->lo[1] / 2 + bx->hi[1] / 2, bx->lo[2] / 2 + bx->hi[2] / 2};
    if (support_beyond(&t->tris[k], c, p, s->thr)) return;
    if (s->n_cheap == CANDS) flush_cheap(t, p, s, st);
    s->cheap[s->n_cheap++] = (cand_t){b * SHRINK, k};
}

/* A leaf's triangles screened, and those left bounded at once: their hi2
 * lowers thr before the descent opens another node (the seed's alone is
 * often loose by orders of magnitude). */
static void leaf(const hd__bvh_t *t, const hd__bvh_node_t *node, const double *p, size_t seed, search_t *s,
                 hd__bvh_stats_t *st) {
    for (size_t k = node->first_or_second, end = k + node->count; k < end; k++)
        if (k != seed) screen(t, p, k, s, st);
    flush_cheap(t, p, s, st);
}

static void search_init(search_t *s) {
    s->index = s->pos = SIZE_MAX;
    s->thr = INFINITY;
    s->n_cheap = s->n_prep = 0;
}

static size_t search_end(const hd__bvh_t *t, const double *p, search_t *s, hd__tri_near_t *best, size_t *index,
                         hd__bvh_stats_t *st) {
    flush_cheap(t, p, s, st);
    flush_prep(t, p, s, st);
    *best = s->best;
    *index = s->index;
    return s->pos;
}

/* The seed: the kernel at once when asked (a best corner early lets
 * corner_tie decide the triangles around it), else a first candidate. */
static void start(const hd__bvh_t *t, const double *p, size_t seed, int seed_kernel, search_t *s,
                  hd__bvh_stats_t *st) {
    search_init(s);
    if (seed >= t->n_tris) return;
    if (seed_kernel) evaluate(t, p, seed, s, st);
    else consider(t, p, seed, s, st);
}

/* The frame bound.  For a node with a frame (hd__bvh_frame_t) and a
 * point p, g_j is a computed gap of p outside slab j: on the hi side, the
 * true gap is gamma_j = a_j . p - hi_j, and t_j, the computed a_j . p, is
 * within gamma_3 |a_j|_1 P + 3 * 2^-1074 <= 5.5u P + 2^-1072 of a_j . p
 * (P = max |p_i|, |a_j|_1 <= 1.8); D = t_j - hi_j rounds by at most
 * u (1.81 P + H) (H = frame_h >= |hi_j|), so |D - gamma_j| <= 7.4u P + uH
 * + 2^-1072, which E = 2^-50 (2P + H) + 2^-1020 (computed, at least
 * 15.9u P + 7.9u H + 0.99 * 2^-1020) exceeds: g_j = D - E, rounded, is at
 * most gamma_j (1 + u) when positive (likewise on the lo side, with
 * gamma_j = lo_j - a_j . p); g_j = 0 elsewhere.  Let s_j = +1 on the hi
 * side, -1 on the lo side, and w = sum s_j g_j a_j (exact).  For every x
 * of the node, a_j . x lies in [lo_j, hi_j], so w . (p - x) >=
 * sum g_j gamma_j >= G / (1 + u) with G = sum g_j^2; and |w|^2 <= G (1 +
 * eta + 2c) <= G (1 + 3 * 2^-44), where |a_j|^2 <= 1 + eta and
 * |a_j . a_k| <= c (frame_axes) and 2 g_j g_k <= g_j^2 + g_k^2.  So by
 * Cauchy-Schwarz |p - x|^2 >= G / ((1 + u)^2 (1 + 3 * 2^-44)).  The
 * computed G is at most G (1 + u)^3 plus 3 * 2^-1074 of underflow, a
 * relative 2^-170 when it is at least 2^-900; G (1 - 2^-40), rounded, is
 * below every such bound.  Returns that lower bound on the squared
 * distance from p to the node, or 0. */
static inline double frame_lo2(const hd__bvh_frame_t *f, const double *p, double E) {
    double G = 0;
    for (int j = 0; j < 3; j++) {
        double d = f->a[j][0] * p[0] + f->a[j][1] * p[1] + f->a[j][2] * p[2];
        double g = (d - f->hi[j]) - E;
        if (!(g > 0)) g = (f->lo[j] - d) - E;
        if (g > 0) G += g * g;
    }
    return G >= 0x1p-900 ? G * (1 - 0x1p-40) : 0.0;
}

/* E of frame_lo2 for the point p. */
static double frame_err(const hd__bvh_t *t, const double *p) {
    double P = fabs(p[0]) > fabs(p[1]) ? fabs(p[0]) : fabs(p[1]);
    P = fabs(p[2]) > P ? fabs(p[2]) : P;
    return 0x1p-50 * (2 * P + t->frame_h) + 0x1p-1020;
}

double hd__bvh_frame_lower2(const hd__bvh_t *t, size_t k, size_t first, size_t n, const double p[3]) {
    if (!t->frames || k >= t->n_nodes || n > FRAME_MAX) return 0.0;
    const hd__bvh_frame_t *f = frame_get(t, (uint32_t)k, (uint32_t)first, (uint32_t)n);
    return f ? frame_lo2(f, p, frame_err(t, p)) : 0.0;
}

/* A lower bound on the squared distance from p to node k: the frame's
 * (frame_lo2) where the node has one and E >= 0, else its box's
 * (hd__box_lb2s times SHRINK: box_beyond's proof). */
static inline double node_lo2(const hd__bvh_t *t, uint32_t k, uint32_t first, uint32_t n, const double *p,
                              double E) {
    const hd__bvh_frame_t *f = E >= 0 && n <= FRAME_MAX ? frame_get(t, k, first, n) : NULL;
    if (f) return frame_lo2(f, p, E);
    return box_lb2s(&t->nodes[k].box, p) * SHRINK;
}

/* The descent of the subtree of node root (holding the triangles
 * [root_first, root_first + root_n)), nearest child first; framed: with
 * the frames (node_lo2 with E), else the boxes alone (written twice by
 * the compiler, one loop each). */
HD__INLINE void descend(const hd__bvh_t *t, const double *p, size_t seed, search_t *s, hd__bvh_stats_t *st,
                        int framed, double E, uint32_t root, uint32_t root_first, uint32_t root_n) {
    E = framed ? E : -1.0;
    /* lo2: a lower bound on the squared distance to the node (node_lo2);
     * [first, first + n): the node's triangles (the build gives a node's
     * first child the first n / 2) */
    typedef struct { uint32_t node, first, n; double lo2; } entry_t;
    entry_t stack[MAX_DEPTH], *e;
    int top = 0;
    stack[top++] = (entry_t){root, root_first, root_n, node_lo2(t, root, root_first, root_n, p, E)};
    while (top > 0) {
        e = &stack[--top];
        if (e->lo2 > s->thr) continue;
        const hd__bvh_node_t *node = &t->nodes[e->node];
        uint32_t first = e->first, n = e->n;
        st->nodes++;
        if (node->count) {
            leaf(t, node, p, seed, s, st);
            continue;
        }
        uint32_t a = e->node + 1, b = node->first_or_second, na = n / 2, fa = first, fb = first + n / 2;
        double la = node_lo2(t, a, fa, na, p, E), lb = node_lo2(t, b, fb, n - na, p, E);
        /* the nearer child on top; the median split halves the count at
         * each level, so the stack never holds more than the depth plus one */
        if (la > lb) {
            if (!(la > s->thr)) stack[top++] = (entry_t){a, fa, na, la};
            if (!(lb > s->thr)) stack[top++] = (entry_t){b, fb, n - na, lb};
        } else {
            if (!(lb > s->thr)) stack[top++] = (entry_t){b, fb, n - na, lb};
            if (!(la > s->thr)) stack[top++] = (entry_t){a, fa, na, la};
        }
    }
}

/* The search from the seed's leaf up.  The leaf holding position seed is
 * found from the positions alone (a node's first child holds its first
 * n / 2 triangles), and its ancestors' other children, the siblings, are
 * kept on the way down.  When the seed's threshold is at most CLIMB_REACH
 * times the squared diagonal of that leaf's box (the point within half
 * the leaf's diagonal of the seed, as a point of a dense scan is of the
 * previous point's nearest triangle), the leaf is searched first and
 * then each sibling's subtree, deepest first (descend, with the boxes):
 * the leaf and the siblings partition the tree, and the file's rule makes
 * the answer independent of the order of visits, so the result is the
 * descent's from the root.  A sibling near the root is far from a point
 * near its seed, and its box alone discards it: the path from the root is
 * walked without a bound, and the nodes a near point opens are those
 * around its leaf.  0 (nothing searched) when the seed is too far. */
#define CLIMB_REACH 0.25
static int climb(const hd__bvh_t *t, const double *p, size_t seed, search_t *s, hd__bvh_stats_t *st) {
    struct { uint32_t node, first, n; } sib[MAX_DEPTH];
    int depth = 0;
    uint32_t k = 0, first = 0, n = (uint32_t)t->n_tris;
    while (!t->nodes[k].count) {
        uint32_t na = n / 2;
        if (seed < (size_t)first + na) {
            sib[depth].node = t->nodes[k].first_or_second, sib[depth].first = first + na, sib[depth++].n = n - na;
            k = k + 1, n = na;
        } else {
            sib[depth].node = k + 1, sib[depth].first = first, sib[depth++].n = na;
            k = t->nodes[k].first_or_second, first += na, n -= na;
        }
    }
    const hd__box_t *b = &t->nodes[k].box;
    double x = b->hi[0] - b->lo[0], y = b->hi[1] - b->lo[1], z = b->hi[2] - b->lo[2];
    if (!(s->thr <= CLIMB_REACH * (x * x + y * y + z * z))) return 0;
    st->nodes++;
    leaf(t, &t->nodes[k], p, seed, s, st);
    while (depth > 0) {
        depth--;
        descend(t, p, seed, s, st, 0, -1.0, sib[depth].node, sib[depth].first, sib[depth].n);
    }
    return 1;
}

size_t hd__bvh_nearest(const hd__bvh_t *t, const double p[3], size_t seed, int seed_kernel, hd__tri_near_t *best,
                       size_t *index, hd__bvh_stats_t *st) {
    search_t s;
    start(t, p, seed, seed_kernel, &s, st);
    /* the frames for a point farther from its seed than two diagonals of
     * the largest framed nodes; the boxes alone nearer, and without a
     * seed (a run's first point: the first leaf reached bounds it) */
    uint32_t n = (uint32_t)t->n_tris;
    if (t->frames && seed < t->n_tris && s.thr > 4 * t->frame_reach2) descend(t, p, seed, &s, st, 1, frame_err(t, p), 0, 0, n);
    else if (seed >= t->n_tris || !climb(t, p, seed, &s, st)) descend(t, p, seed, &s, st, 0, -1.0, 0, 0, n);
    return search_end(t, p, &s, best, index, st);
}

/* ---- a group of points sharing one list --------------------------------- */

/* The box-to-box bound has the box bound's error (one rounding per
 * difference, square and sum): the same SHRINK proves it. */
static int boxes_beyond(const hd__box_t *a, const hd__box_t *b, double r2) {
    return hd__box_box_lb2(a, b) * SHRINK > r2;
}

/* The support bound between a triangle and a box B: with w the computed
 * centre of B less c (the centre of the triangle's box), every q of B and
 * x of the triangle have w . (q - x) = w . (q - c) - w . (x - c) >=
 * sum_i min(w_i (lo_i - c_i), w_i (hi_i - c_i)) - max_k w . x_k, and
 * |q - x| >= w . (q - x) / |w|.  Rounding: each of the terms is formed by
 * a rounded difference and a rounded product (2.01u of the larger of its
 * two computed magnitudes, a_i), the three summed (2.01u of their sum),
 * and w . x_k as in support_beyond (4.1u A_k); the three subtractions
 * below round by at most u of |Q| + |M| + E each: E = 2^-48 (sum a_i +
 * max A_k) + 2^-1000 exceeds all of it (32u against 11u), and the test
 * then is support_beyond's with r2 for thr. */
static int group_beyond(const hd__tri_t *t, const hd__box_t *tb, const hd__box_t *B, double r2) {
    double c[3], w[3], Q = 0, S = 0;
    for (int i = 0; i < 3; i++) {
        c[i] = tb->lo[i] / 2 + tb->hi[i] / 2;
        w[i] = (B->lo[i] / 2 + B->hi[i] / 2) - c[i];
    }
    double W2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    if (!(W2 >= 0x1p-900)) return 0;
    for (int i = 0; i < 3; i++) {
        double x = w[i] * (B->lo[i] - c[i]), y = w[i] * (B->hi[i] - c[i]);
        Q += x < y ? x : y;
        S += fabs(x) > fabs(y) ? fabs(x) : fabs(y);
    }
    double M = -INFINITY, A = 0;
    for (int k = 0; k < 3; k++) {
        const double *v = t->v[k];
        double x0 = v[0] - c[0], x1 = v[1] - c[1], x2 = v[2] - c[2];
        double sk = w[0] * x0 + w[1] * x1 + w[2] * x2;
        double Ak = fabs(w[0] * x0) + fabs(w[1] * x1) + fabs(w[2] * x2);
        M = sk > M ? sk : M;
        A = Ak > A ? Ak : A;
    }
    double num = ((Q - M) - (0x1p-48 * (S + A) + 0x1p-1000)) * (1 - 0x1p-50);
    if (!(num > 0)) return 0;
    double rhs = r2 * W2 * (1 + 0x1p-49);
    return rhs >= 0x1p-1000 && num * num * (1 - 0x1p-50) > rhs;
}

size_t hd__bvh_collect(const hd__bvh_t *t, const hd__box_t *B, double r2, uint32_t *out, size_t cap) {
    uint32_t stack[MAX_DEPTH];
    int top = 0;
    size_t n = 0;
    if (boxes_beyond(&t->nodes[0].box, B, r2)) return 0;
    stack[top++] = 0;
    while (top > 0) {
        const hd__bvh_node_t *node = &t->nodes[stack[--top]];
        if (node->count) {
            for (size_t k = node->first_or_second, end = k + node->count; k < end; k++) {
                if (boxes_beyond(&t->boxes[k], B, r2) || group_beyond(&t->tris[k], &t->boxes[k], B, r2)) continue;
                if (n == cap) return SIZE_MAX;
                out[n++] = (uint32_t)k;
            }
            continue;
        }
        uint32_t a = (uint32_t)(node - t->nodes) + 1, b = node->first_or_second;
        if (!boxes_beyond(&t->nodes[b].box, B, r2)) stack[top++] = b;
        if (!boxes_beyond(&t->nodes[a].box, B, r2)) stack[top++] = a;
    }
    return n;
}

size_t hd__bvh_nearest_in(const hd__bvh_t *t, const double p[3], const uint32_t *list, size_t n, size_t seed,
                          int seed_kernel, hd__tri_near_t *best, size_t *index, hd__bvh_stats_t *st) {
    search_t s;
    start(t, p, seed, seed_kernel, &s, st);
    for (size_t i = 0; i < n; i++) {
        size_t k = list[i];
        if (k != seed) screen(t, p, k, &s, st);
    }
    st->listed += n;
    return search_end(t, p, &s, best, index, st);
}
