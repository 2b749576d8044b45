/*
 * m2m.c -- the distance from a surface to a surface, enclosed: branch and
 * bound over the triangles of X (the side measured from) against the tree
 * of Y's triangles (a point set is a tree of point-triangles).
 *
 * Sub-triangles.  A sub-triangle of a face abc of X is kept as three
 * corners, each with exact integer barycentric weights (k0, k1, k2),
 * k0 + k1 + k2 = 2^L at the sub-triangle's level L; splitting at the edge
 * midpoints doubles the weights of the old corners and adds those of two
 * corners for a midpoint, so the four children tile their parent exactly
 * (in real arithmetic) and the leaves of a face tile the face.  Levels
 * stop at MAX_LEVEL (weights below 2^63).
 *
 * Computed corners.  A corner's point is computed in doubles as
 * x = fl(a + fl(fl(w1 fl(b - a)) + fl(w2 fl(c - a)))) with w = fl(k) 2^-L
 * (each weight off by at most u w, u = 2^-53; ldexp is exact for
 * 2^-62 <= w <= 1).  Per coordinate, with s* = w1 (b - a) + w2 (c - a)
 * and the computed sum s: each product is within gamma_3 of w (b - a)
 * (difference, weight, product), so |s - s*| <= (gamma_3 + u (1 +
 * gamma_3)) (w1 |b - a| + w2 |c - a|) + 3 2^-1075 <= 4.01 u D_k + 2^-1073
 * with D_k = max(|b_k - a_k|, |c_k - a_k|) (w1 + w2 <= 1), and the last
 * addition adds at most u |a + s| <= u M_k (1 + 5u) with M_k the largest
 * |coordinate k| of the corners (x* lies in their hull).  Over the three
 * coordinates: at most 1.01 u (Mx + My + Mz) + 4.01 u (Dx + Dy + Dz) +
 * 2^-1071.  slack() uses e = 2 u sum M + 8 u sum D + 2^-1060 (the computed
 * differences are within a factor 1 + u of the exact ones).  A corner that
 * is a vertex of the face (one weight 2^L) is that vertex, exactly
 * (e = 0).
 *
 * Bounds.  Each corner v gets hi >= d(v, Y) from the prepared bounds alone
 * (interval(): the smallest hi2 of hd__tri_bounds_prep over the triangles of
 * Y that the tree cannot exclude), and the triangle giving it.  The exact
 * r = RN(d(v, Y)) (the kernel through the tree, hd__bvh_nearest) is needed
 * only where v could change the lower bound: r <= hi (RN is monotone and
 * hi is a double), so a corner whose lower bound from hi (below) is at most
 * the bound it would have to beat - its face's best and, unless each
 * face's own lower bound is asked for, L - cannot beat it (offer() needs
 * more), and the result is the same as with every r computed.  Phase 0's
 * bar is max lo over all corners (lo <= d from the smallest lo2 of the
 * triangles visited): a corner with hi below it is nearer than another.
 * An exact corner takes hi = next_up(r) when that is smaller.
 *  - Lower: a point of X at distance >= r' from Y with r' = r at a vertex
 *    (the witness is exact), else r' = down(next_down(r) - e): the exact
 *    point of the face at the corner's weights is within e of v, so its
 *    distance is at least d(v, Y) - e >= next_down(r) - e.
 *  - Upper, for the hull T of the three computed corners: every y in T has
 *    d(y, Y) <= d(v, Y) + |y - v| for each corner v, so
 *    d(y, Y) <= max_v hi_v + R with R >= the largest distance from a
 *    point of T to its nearest corner (the point bound: R <= the longest
 *    edge over sqrt 3 for every triangle, the circumradius bound of a
 *    non-obtuse triangle, and half the longest edge for an obtuse one).
 *    And for any triangle t of Y, d(., t) is convex, so its maximum over T
 *    is at a corner: d(y, Y) <= min over t of max_v d(v, t) (Tang et al.),
 *    taken over the corners' nearest triangles with d(v, t) <= sqrt_up(hi2)
 *    from hd__tri_bounds (or hi for v's own triangle), and, for a child
 *    those leave above the threshold, the triangle nearest (as the bounds
 *    tell) to its corners' centroid computed in doubles (any triangle
 *    gives a bound; where does not matter for rigor).  Two triangles t1,
 *    t2 at once (bent pairs, whose corners are nearest to different
 *    triangles): with a_k >= d(v_k, t1), b_k >= d(v_k, t2) and y =
 *    sum w_k v_k in T, convexity gives d(y, ti) <= sum w_k a_k (resp.
 *    b_k), and for any lam in [0, 1] and mu >= 1 - lam, min(x, z) <=
 *    lam x + mu z for x, z >= 0, so d(y, Y) <= sum w_k (lam a_k + mu b_k)
 *    <= max_k (lam a_k + mu b_k): a bound for every lam (no face region,
 *    sign or rounding of lam matters; mu = next_up(1 - lam) and each
 *    product and sum is moved one double up).  The smallest over lam of
 *    this convex piecewise linear function is at lam = 0, 1 (Tang's) or
 *    where two corners' lines cross, and equals the largest over T of
 *    min(sum w_k a_k, sum w_k b_k) (minimax over two simplices), so those
 *    lam are the ones tried.  The exact
 *    sub-triangle of the face is within e of T point by point (the weights
 *    of a point of the exact sub-triangle applied to the computed corners
 *    give a point of T within e), so U = up(min(both) + e) (e = 0 at level
 *    0, whose corners are exact).
 * All upper sums and square roots are rounded to nearest and then moved one
 * double up (next_up), which is at least the exact value.
 *
 * The search.  Phase 0 bounds a sample of the corners in full and
 * computes the exact distances of those that can be the largest; the best,
 * L0, is the distance of a vertex of X.  It then bounds every other
 * distinct corner, each search stopping at the first triangle whose hi is
 * at most a target below L0 (any triangle's hi is >= d(v, Y), so hi stays
 * an upper bound; such a corner cannot beat L0 and needs no exact
 * distance; its lo is then 0, since the triangles not visited were not
 * excluded), and computes the exact distances of the corners whose hi
 * reaches L0 and every complete search's lo.  A corner whose bound carried
 * from the last corner searched in its chunk (the anchor a, with hi_a >=
 * d(a, t) for t the triangle at its pos) meets that target is not searched:
 * d(v, t) <= hi_a + |v - a| (hd__m2m_carried_bound, rounded up) is an
 * upper bound with the anchor's triangle, which is all phases 1 and 2 ask
 * of a corner's hi and pos (bench/m2m_run, `through`).  A midpoint's search stops
 * the same way at a bound within the tolerance of the threshold (less the
 * slack) and below the bar of exact corners (split()).  Phase 1 evaluates
 * every face's corners (fixed chunks, any thread) and sets the lower
 * bound L to the best corner.  Phase 2 takes the faces by decreasing
 * upper bound in batches of fixed sizes; the faces of a batch are refined
 * in parallel, each on its own against L as it was before the batch (and
 * its own corners' lower bounds): a face pops its sub-triangle of largest
 * U, stops when U <= max(L, own lower) + tolerance (or the predicate's
 * bound), else splits it and keeps the children whose U exceeds that
 * threshold.  A visit ends after a budget of splits (growing fourfold from
 * pass to pass); the faces left pending are taken again, by their bounds
 * so far, in the next pass, so that no face is refined to the end against
 * an L that a face with a higher bound would raise.  The batches merge in
 * order, the witness is the first best in face order, so nothing depends
 * on the thread count.  The face's upper bound is the largest U it stopped
 * at or discarded (or, pending when the search stopped, the largest U
 * left); h's upper bound is the largest over faces (faces skipped because
 * their first U was <= L contribute that U).
 *
 * Candidate lists.  A sub-triangle split at level LIST_LEVEL or deeper
 * bounds its midpoints from a list of Y's triangles instead of the tree
 * (evaluate_in; any triangle's bound is an upper bound, so the list only
 * decides how tight hi is, never whether it holds).  The list holds
 * every triangle that can be nearest to a point q computed below the
 * sub-triangle s (a corner of a descendant): q is within e of the exact
 * point of the face at its weights, which lies in the exact sub-triangle,
 * itself within e of the hull T of s's computed corners point by point
 * (above), so |q - y| <= 2e for some y in T and d(q, Y) <= d(y, Y) + 2e
 * <= U + 2e <= H = up(U + 2e), U = s's bound; and q lies in the corners'
 * box widened by 2e (rounded outward), Bx.  q's nearest triangle t* has
 * dist(Bx, box(t*)) <= d(q, t*) = d(q, Y) <= H, so t* is not among the
 * triangles whose box is proven farther than sqrt(r2) from Bx, r2 =
 * up(H * H) >= H^2 (box_far: the computed box-to-box square is within
 * (1 + u)^5 of the exact one above 2^-1000, and is shrunk by 1 - 2^-46).
 * The children's points are their parent's, so they inherit its list as
 * it stands; a sub-triangle being split filters its inherited list with
 * its own Bx and H (the same argument), or, without one, collects it from
 * the tree (hd__bvh_collect, up to LIST_MAX triangles: it leaves out only
 * triangles proven farther than sqrt(r2) from Bx, by their boxes or by
 * the support bound, proofs in bvh.c).  Lists live in the
 * worker's arena for one visit of the face; a sub-triangle saved for a
 * later pass loses its list.  So hi is the tree's smallest hi2, up to
 * ties, and every list depends on the face's refinement alone.
 *
 * Corners remember (MEMO) the bounds to triangles of Y that upper_of
 * computed for them (corner_to: a function of the point and the triangle
 * only), so a corner shared by siblings, or kept by the children of a
 * split, is bounded once per triangle; the results are the same.
 *
 * The predicate (a finite d: done_below = stop_above = d) runs phases 0
 * and 1 in rounds of faces instead: a face is first screened - the point
 * bound over its vertices from any triangle of Y whose prepared upper
 * bound is small enough, or Tang's bound with one such triangle - and
 * discarded unrefined when that is <= d; only the other faces' corners are
 * measured, and a lower bound above d after a round ends the search (the
 * faces not reached then have no bound: upper is infinite).  Refinement
 * discards every sub-triangle whose U is <= d and stops a face at a lower
 * bound above d.
 */
#include "mesh/mesh.h"
#include "mesh/mesh_int.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_LEVEL 62
/* The batches of phase 2: FIRST_BATCH faces, doubling up to MAX_BATCH. */
#define FIRST_BATCH 8
#define MAX_BATCH 1024
/* Faces per task in phase 1. */
#define CHUNK 256
/* Phase 0's sample: every stride-th corner in Morton order, the stride
 * SAMPLE_STRIDE doubled while the sample would exceed SAMPLE_SIZE corners,
 * up to MAX_STRIDE (each sample corner is searched in full; a larger
 * sample only sharpens L0 a little: bench/m2m_run, `through` and
 * `decimated` against `shared`). */
#define SAMPLE_STRIDE 32
#define SAMPLE_SIZE 512
#define MAX_STRIDE 256
/* Below this a squared edge may have underflowed: R from |dx|+|dy|+|dz|. */
#define TINY2 0x1p-960

/* The next double up (down) from a finite x, as nextafter(x, +-infinity)
 * gives it (inline: the bounds take several a sub-triangle). */
static double up(double x) {
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    if (x == 0) return 0x1p-1074;
    if (!isfinite(x)) return x;
    b += x > 0 ? 1 : (uint64_t)-1;
    memcpy(&x, &b, sizeof b);
    return x;
}
static double down(double x) { return -up(-x); }
/* fmax and fmin (a NaN argument gives the other), inline: libm's are calls. */
static inline double dmax(double a, double b) { return a > b ? a : b == b ? b : a; }
static inline double dmin(double a, double b) { return a < b ? a : b == b ? b : a; }
static double sqrt_up(double x) { return x <= 0 ? 0 : up(sqrt(x)); }

/* Bounds to triangles of Y that a corner remembers (corner_to). */
#define MEMO 4

typedef struct corner {
    double p[3];
    uint64_t k[3];
    double hi;     /* d(p, Y) <= hi, and d(p, t) <= hi for t at pos */
    double r;      /* RN(d(p, Y)), when exact */
    double lower;  /* a distance a point of X has, from this corner (exact) */
    size_t pos;    /* a triangle of Y as near as the bounds tell: its position */
    size_t index;  /* p's nearest triangle's index in Y (exact) */
    double near[3];/* the nearest point on it (exact) */
    int exact;     /* r, lower, index, near are set */
    /* bounds already computed: d(p, triangle at mpos[i]) <= mh[i]
     * (corner_to's value, a function of p and the triangle alone) */
    uint32_t mpos[MEMO];
    double mh[MEMO];
    int nm;
} corner_t;

typedef struct sub {
    corner_t c[3];
    double U;
    int level;
    /* candidates: list[off, off + n) of the worker's arena holds every
     * triangle of Y that can be nearest to a point of the sub-triangle's
     * descendants (inherited from the parent, or its own once split;
     * n == NO_LIST: none, the tree is searched) */
    uint32_t off, n;
} sub_t;
#define NO_LIST UINT32_MAX

/* The best lower bound of a face and its witness. */
typedef struct best {
    double lower;
    int set;
    corner_t c;
    int level;
    double e;
} best_t;

/* A face's state between the phases and its result. */
typedef struct face {
    sub_t top;          /* level 0 */
    best_t best;
    double upper;       /* the face's upper bound so far */
    uint64_t splits, kernel;
    int capped;         /* stopped by max_splits or MAX_LEVEL */
    int done;
    /* a face whose visit used up its budget: its sub-triangles still to
     * refine, in the order the heap gave them, and the largest U discarded */
    sub_t *saved;
    size_t n_saved;
    double cut;
} face_t;

static double slack(const hd__tri_t *t) {
    double m = 0, d = 0;
    for (int k = 0; k < 3; k++) {
        double mk = dmax(fabs(t->v[0][k]), dmax(fabs(t->v[1][k]), fabs(t->v[2][k])));
        double dk = dmax(fabs(t->v[1][k] - t->v[0][k]), fabs(t->v[2][k] - t->v[0][k]));
        m = up(m + mk);
        d = up(d + dk);
    }
    return up(up(m * 0x1p-52 + d * 0x1p-50) + 0x1p-1060);
}

/* The corner's point from its weights at `level` (see the top). */
static void corner_point(const hd__tri_t *t, corner_t *c, int level) {
    uint64_t one = (uint64_t)1 << level;
    for (int j = 0; j < 3; j++)
        if (c->k[j] == one) {
            memcpy(c->p, t->v[j], sizeof c->p);
            return;
        }
    double w1 = ldexp((double)c->k[1], -level), w2 = ldexp((double)c->k[2], -level);
    for (int d = 0; d < 3; d++) {
        double d1 = t->v[1][d] - t->v[0][d], d2 = t->v[2][d] - t->v[0][d];
        c->p[d] = t->v[0][d] + (w1 * d1 + w2 * d2);
    }
}

static int is_vertex(const corner_t *c, int level) {
    uint64_t one = (uint64_t)1 << level;
    return c->k[0] == one || c->k[1] == one || c->k[2] == one;
}

static void offer(best_t *b, const corner_t *c, int level, double e) {
    if (!b->set || c->lower > b->lower) {
        b->set = 1;
        b->lower = c->lower;
        b->c = *c;
        b->level = level;
        b->e = is_vertex(c, level) ? 0 : e;
    }
}

/* R for a sub-triangle whose squared edges may have underflowed: the
 * perimeter in the 1-norm, each step rounded up (taken only then: the
 * squares decide when). */
static double tiny_reach(const sub_t *s) {
    double l1 = 0;
    for (int i = 0; i < 3; i++) {
        const double *p = s->c[i].p, *q = s->c[(i + 1) % 3].p;
        double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
        l1 = up(l1 + up(up(fabs(dx) + fabs(dy)) + fabs(dz)));
    }
    return up(l1 * (1 + 0x1p-40));
}

/* R: the farthest a point of the hull of the corners can be from its
 * nearest corner, rounded up (see the top). */
static double reach(const sub_t *s) {
    double l2[3];
    for (int i = 0; i < 3; i++) {
        const double *p = s->c[i].p, *q = s->c[(i + 1) % 3].p;
        double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
        l2[i] = dx * dx + dy * dy + dz * dz;
    }
    double a2 = dmax(l2[0], dmax(l2[1], l2[2]));
    if (a2 < TINY2) return tiny_reach(s);
    double rest = l2[0] + l2[1] + l2[2] - a2;
    /* a2 > rest by a margin far above the rounding of the squares: obtuse */
    double f = a2 > rest * (1 + 0x1p-40) ? 0.5 : 0.57735026918962584;
    return up(sqrt(a2) * f * (1 + 0x1p-40));
}

/* ---- two coplanar triangles whose union is convex ----------------------- */

/* Exactly: p q a and p q b are coplanar, on opposite sides of pq, and the
 * quadrilateral a p b q is convex (segment ab meets line pq between p and
 * q), so that the union of the two triangles is a convex set.  A filter in
 * doubles rejects the clearly non-coplanar first. */
static int filtered_apart(const double *p, const double *q, const double *a, const double *b) {
    double u[3], x[3], y[3];
    for (int i = 0; i < 3; i++) u[i] = q[i] - p[i], x[i] = a[i] - p[i], y[i] = b[i] - p[i];
    double c0 = u[1] * y[2] - u[2] * y[1], c1 = u[2] * y[0] - u[0] * y[2], c2 = u[0] * y[1] - u[1] * y[0];
    double det = x[0] * c0 + x[1] * c1 + x[2] * c2;
    double perm = fabs(x[0]) * (fabs(u[1] * y[2]) + fabs(u[2] * y[1])) +
                  fabs(x[1]) * (fabs(u[2] * y[0]) + fabs(u[0] * y[2])) +
                  fabs(x[2]) * (fabs(u[0] * y[1]) + fabs(u[1] * y[0]));
    return fabs(det) > perm * 0x1p-48 + 0x1p-1000;
}

static void big_cross(hd__big_t r[3], const hd__big_t x[3], const hd__big_t y[3]) {
    hd__big_t s, t;
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        hd__big_mul(&s, &x[j], &y[k]);
        hd__big_mul(&t, &x[k], &y[j]);
        hd__big_sub(&r[i], &s, &t);
    }
}

static int big_dot_sign(const hd__big_t x[3], const hd__big_t y[3]) {
    hd__big_t s, t, acc;
    hd__big_set_u64(&acc, 0);
    for (int i = 0; i < 3; i++) {
        hd__big_mul(&s, &x[i], &y[i]);
        hd__big_add(&t, &acc, &s);
        acc = t;
    }
    return hd__big_sign(&acc);
}

static int convex_pair(const double *p, const double *q, const double *a, const double *b) {
    if (filtered_apart(p, q, a, b)) return 0;
    const double *in[4] = {p, q, a, b};
    int e0 = 0, any = 0;
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++)
            if (in[i][k] != 0) {
                int e = hd__ulp_exp(in[i][k]);
                e0 = !any || e < e0 ? e : e0;
                any = 1;
            }
    if (!any) return 0;
    hd__big_t P[4][3], u[3], x[3], y[3], w[3], na[3], nb[3], c[3];
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++) hd__big_set_double(&P[i][k], in[i][k], e0);
    for (int k = 0; k < 3; k++) {
        hd__big_sub(&u[k], &P[1][k], &P[0][k]);
        hd__big_sub(&x[k], &P[2][k], &P[0][k]);
        hd__big_sub(&y[k], &P[3][k], &P[0][k]);
        hd__big_sub(&w[k], &P[3][k], &P[2][k]);
    }
    big_cross(na, u, x);
    big_cross(nb, u, y);
    big_cross(c, na, nb);
    for (int k = 0; k < 3; k++)
        if (hd__big_sign(&c[k]) != 0) return 0; /* not coplanar */
    if (big_dot_sign(na, nb) >= 0) return 0;         /* same side, or degenerate */
    hd__big_t pa[3], qa[3], mp[3], mq[3];
    for (int k = 0; k < 3; k++) {
        hd__big_sub(&pa[k], &P[0][k], &P[2][k]);
        hd__big_sub(&qa[k], &P[1][k], &P[2][k]);
    }
    big_cross(mp, w, pa);
    big_cross(mq, w, qa);
    return big_dot_sign(mp, mq) <= 0; /* p and q on opposite sides of ab */
}

/* When triangles s and t of the tree share an edge and their union is
 * convex: 1, with the shared corners p, q and the others a (of s), b. */
static int shared_convex(const hd__tri_t *s, const hd__tri_t *t) {
    int same[3] = {-1, -1, -1}, n = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3 && same[i] < 0; j++)
            if (memcmp(s->v[i], t->v[j], sizeof s->v[i]) == 0) same[i] = j, n++;
    if (n != 2) return 0;
    int ia = same[0] < 0 ? 0 : same[1] < 0 ? 1 : 2, ip = (ia + 1) % 3, iq = (ia + 2) % 3;
    /* two corners of s equal to one corner of t (s has repeated corners):
     * no shared edge */
    if (same[ip] == same[iq]) return 0;
    int jb = 3 - same[ip] - same[iq];
    return convex_pair(s->v[ip], s->v[iq], s->v[ia], t->v[jb]);
}

/* A worker's prepared triangles of Y, by position in the tree (direct
 * mapped, a power of two entries up to MAX_CACHE, enough for all of Y
 * when it is smaller): hd__tri_bounds_prep gives hd__tri_bounds's bits,
 * so what the cache holds never changes a result. */
#define MAX_CACHE 2048
typedef struct cache {
    size_t mask;
    size_t *pos;
    hd__tri_prep_t *prep;
} cache_t;

static void caches_free(cache_t *C, int n) {
    for (int w = 0; C && w < n; w++) {
        free(C[w].pos);
        free(C[w].prep);
    }
    free(C);
}

/* n workers' caches for a tree of n_tris triangles, or NULL. */
static cache_t *caches_new(int n, size_t n_tris) {
    size_t size = 64;
    while (size < n_tris && size < MAX_CACHE) size *= 2;
    cache_t *C = calloc((size_t)n, sizeof *C);
    for (int w = 0; C && w < n; w++) {
        C[w].mask = size - 1;
        C[w].pos = hd__malloc_array(size, sizeof *C[w].pos);
        C[w].prep = hd__malloc_array(size, sizeof *C[w].prep);
        if (!C[w].pos || !C[w].prep) {
            caches_free(C, n);
            return NULL;
        }
        for (size_t k = 0; k < size; k++) C[w].pos[k] = SIZE_MAX;
    }
    return C;
}

static const hd__tri_prep_t *prepared(cache_t *C, size_t pos, const hd__tri_t *t) {
    size_t k = pos & C->mask;
    if (C->pos[k] != pos) {
        hd__tri_prep(t->v[0], t->v[1], t->v[2], &C->prep[k]);
        C->pos[k] = pos;
    }
    return &C->prep[k];
}

/* ---- a point's distance to Y, enclosed without the kernel --------------- */

/* Every point of the box is at squared distance above h2 from p (the
 * computed hd__box_lb2s is within a factor (1 + u)^11 of the exact square
 * when it is at least 2^-1000, bvh.c's proof). */
static int far2(double s, double h2) { return s >= 0x1p-1000 && s * (1 - 0x1p-46) > h2; }
static int beyond(const hd__box_t *b, const double p[3], double h2) { return far2(hd__box_lb2s(b, p[0], p[1], p[2]), h2); }

/* The bounds of p to the triangle at pos.  hd__tri_bounds gives lo2 = 0 for
 * a point (a point set's triangles): there the computed square, within a
 * factor 1 + 5.01 u of the exact one (two roundings in each difference
 * squared, two in the sum), shrunk by 1 - 8 u. */
static void bounds_at(const hd__bvh_t *T, size_t pos, const double p[3], cache_t *C, double *lo2, double *hi2) {
    const hd__tri_t *t = &T->tris[pos];
    hd__tri_bounds_prep(p, prepared(C, pos, t), lo2, hi2);
    if (*lo2 == 0 && memcmp(t->v[0], t->v[1], sizeof t->v[0]) == 0 && memcmp(t->v[0], t->v[2], sizeof t->v[0]) == 0) {
        double dx = p[0] - t->v[0][0], dy = p[1] - t->v[0][1], dz = p[2] - t->v[0][2];
        double d2 = dx * dx + dy * dy + dz * dz;
        *lo2 = d2 >= 0x1p-1000 ? d2 * (1 - 0x1p-50) : 0;
    }
}

#define DEPTH 130
/* lo <= d(p, Y) <= hi from hd__tri_bounds_prep alone: hi from the triangle
 * of smallest hi2 (returned: its position in the tree; a triangle whose
 * box lies beyond the smallest hi2 so far is skipped), lo from the smallest
 * lo2 over the triangles visited (a skipped one is farther than the
 * nearest, so the minimum over Y is among them).  With enough2 >= 0 the
 * search stops at the first triangle whose hi2 is at most enough2 (the
 * caller needs no smaller upper bound): hi is then that triangle's bound,
 * still >= d(p, Y), and lo is 0 (the triangles not visited were not
 * excluded).  The answer depends on p, the seed, enough2 and the tree
 * only. */
static size_t interval(const hd__bvh_t *T, const double p[3], size_t seed, cache_t *C, double enough2, double *lo,
                       double *hi, uint64_t *count) {
    double best = INFINITY, low = INFINITY, lo2, hi2;
    size_t pos = SIZE_MAX;
    if (seed < T->n_tris) {
        bounds_at(T, seed, p, C, &lo2, &hi2);
        best = hi2, low = lo2, pos = seed;
        (*count)++;
        if (best <= enough2) goto early;
    }
    struct { uint32_t id; double s; } stack[DEPTH]; /* s: the box's hd__box_lb2s */
    int top = 0;
    stack[top].id = 0, stack[top++].s = hd__box_lb2s(&T->nodes[0].box, p[0], p[1], p[2]);
    while (top > 0) {
        uint32_t id = stack[--top].id;
        if (far2(stack[top].s, best)) continue;
        const hd__bvh_node_t *node = &T->nodes[id];
        if (node->count) {
            for (size_t k = node->first_or_second; k < (size_t)node->first_or_second + node->count; k++) {
                if (k == seed || beyond(&T->boxes[k], p, best)) continue;
                bounds_at(T, k, p, C, &lo2, &hi2);
                (*count)++;
                low = dmin(low, lo2);
                if (pos == SIZE_MAX || hi2 < best) best = hi2, pos = k;
                if (best <= enough2) goto early;
            }
            continue;
        }
        uint32_t a = id + 1, b = node->first_or_second;
        double la = hd__box_lb2s(&T->nodes[a].box, p[0], p[1], p[2]);
        double lb = hd__box_lb2s(&T->nodes[b].box, p[0], p[1], p[2]);
        if (la < lb) { /* the nearer on top */
            uint32_t t = a;
            double u = la;
            a = b, la = lb, b = t, lb = u;
        }
        if (!far2(la, best)) stack[top].id = a, stack[top++].s = la;
        if (!far2(lb, best)) stack[top].id = b, stack[top++].s = lb;
    }
    *lo = low > 0 ? down(sqrt(low)) : 0;
    *hi = sqrt_up(best);
    return pos;
early:
    *lo = 0;
    *hi = sqrt_up(best);
    return pos;
}

/* The squared distance below which an upper bound needs no search: a
 * corner whose hi is at most `target` (when target > 0; else none). */
static double enough_of(double target) { return target > 0 ? target * target * (1 - 0x1p-40) : -1; }

/* The largest lower bound the corner could give (its exact distance is at
 * most hi). */
static double could(const corner_t *c, int level, double e) {
    return is_vertex(c, level) ? c->hi : dmax(0.0, down(down(c->hi) - e));
}

/* The corner's exact distance through the tree (the witness's lower bound). */
static void make_exact(const hd__m2m_job_t *J, corner_t *c, int level, double e, hd__bvh_stats_t *st) {
    hd__tri_near_t near;
    size_t pos = hd__bvh_nearest(J->to, c->p, c->pos, 0, &near, &c->index, st);
    c->r = near.d;
    memcpy(c->near, near.point, sizeof c->near);
    c->lower = is_vertex(c, level) ? c->r : dmax(0.0, down(down(c->r) - e));
    c->exact = 1;
    if (up(c->r) < c->hi) c->hi = up(c->r), c->pos = pos;
}

/* The corner's point and its upper bound; the search stops at a bound of
 * `target` or less (see enough_of). */
static void evaluate(const hd__m2m_job_t *J, const hd__tri_t *t, corner_t *c, int level, size_t seed, double target,
                     cache_t *C, uint64_t *count) {
    double lo;
    corner_point(t, c, level);
    c->pos = interval(J->to, c->p, seed, C, enough_of(target), &lo, &c->hi, count);
    c->exact = 0;
}

/* evaluate()'s upper bound from a list of candidates instead of the tree:
 * hi from the smallest hi2 over the seed and the list's triangles whose
 * box is not beyond the best so far (any triangle's sqrt_up(hi2) is
 * >= d(p, Y), so the bound holds whatever the list; a list that holds
 * p's nearest triangle gives the tree's smallest hi2), the search
 * stopping at a bound of target or less as in interval().  The answer
 * depends on p, the seed, the list and target only. */
static void evaluate_in(const hd__m2m_job_t *J, const hd__tri_t *t, corner_t *c, int level, size_t seed,
                        double target, const uint32_t *list, size_t n, cache_t *C, uint64_t *count) {
    const hd__bvh_t *T = J->to;
    double best = INFINITY, enough2 = enough_of(target), lo2, hi2;
    size_t pos = SIZE_MAX;
    corner_point(t, c, level);
    c->exact = 0;
    if (seed < T->n_tris) {
        bounds_at(T, seed, c->p, C, &lo2, &hi2);
        best = hi2, pos = seed;
        (*count)++;
    }
    for (size_t i = 0; i < n && !(best <= enough2); i++) {
        size_t k = list[i];
        if (k == seed || beyond(&T->boxes[k], c->p, best)) continue;
        bounds_at(T, k, c->p, C, &lo2, &hi2);
        (*count)++;
        if (pos == SIZE_MAX || hi2 < best) best = hi2, pos = k;
    }
    if (pos == SIZE_MAX) { /* no seed, an empty list: the tree */
        evaluate(J, t, c, level, seed, target, C, count);
        return;
    }
    c->pos = pos;
    c->hi = sqrt_up(best);
}

/* d(v, t) <= this (v's own nearest triangle: next_up(r)). */
static double corner_to(corner_t *c, size_t pos, const hd__tri_t *t, cache_t *C, uint64_t *kernel) {
    if (c->pos == pos) return c->hi;
    int n = c->nm < MEMO ? c->nm : MEMO;
    for (int i = 0; i < n; i++)
        if (c->mpos[i] == pos) return c->mh[i];
    double lo2, hi2;
    hd__tri_bounds_prep(c->p, prepared(C, pos, t), &lo2, &hi2);
    (*kernel)++;
    double h = sqrt_up(hi2);
    if (pos < UINT32_MAX) {
        c->mpos[c->nm % MEMO] = (uint32_t)pos, c->mh[c->nm % MEMO] = h;
        c->nm = c->nm < MEMO ? c->nm + 1 : MEMO + (c->nm + 1) % MEMO; /* once full: the oldest next */
    }
    return h;
}

/* Over a convex union W of two triangles of Y, the distance to W is convex
 * too: its largest value over the sub-triangle is at a corner. */
static double pair_bound(const hd__m2m_job_t *J, sub_t *s, double U, cache_t *C, uint64_t *kernel) {
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++) {
            size_t p1 = s->c[i].pos, p2 = s->c[j].pos;
            if (p1 == p2) continue;
            const hd__tri_t *t1 = &J->to->tris[p1], *t2 = &J->to->tris[p2];
            if (!shared_convex(t1, t2)) continue;
            double m = 0;
            for (int k = 0; k < 3 && m < U; k++)
                m = dmax(m, dmin(corner_to(&s->c[k], p1, t1, C, kernel), corner_to(&s->c[k], p2, t2, C, kernel)));
            U = dmin(U, m);
        }
    return U;
}

/* The corners' bounds to up to three triangles of Y (the corners' own
 * nearest as the bounds tell, each once), filled as needed: h[i][k] >=
 * d(corner k, triangle i), NAN while not computed. */
typedef struct cands {
    size_t pos[3];
    int n;
    double h[3][3];
} cands_t;

static double cand_h(const hd__m2m_job_t *J, sub_t *s, cands_t *K, int i, int k, cache_t *C, uint64_t *kernel) {
    if (isnan(K->h[i][k])) K->h[i][k] = corner_to(&s->c[k], K->pos[i], &J->to->tris[K->pos[i]], C, kernel);
    return K->h[i][k];
}

/* The largest over the corners of lam a_k + mu b_k, rounded up, with
 * mu >= 1 - lam (a, b >= 0 and finite). */
static double mixed(const double *a, const double *b, double lam) {
    double mu = up(1 - lam), m = 0;
    for (int k = 0; k < 3; k++) m = dmax(m, up(up(lam * a[k]) + up(mu * b[k])));
    return m;
}

/* The bent-pair bound (mesh.h; the proof is at the top): lam is tried at
 * the crossings of the corners' lines lam a_k + (1 - lam) b_k, where the
 * smallest of their maxima lies; any lam in [0, 1] gives a bound. */
double hd__m2m_bent_bound(const double a[3], const double b[3], double U) {
    for (int k = 0; k < 3; k++)
        if (!isfinite(a[k]) || !isfinite(b[k])) return U;
    U = dmin(U, dmin(dmax(a[0], dmax(a[1], a[2])), dmax(b[0], dmax(b[1], b[2])))); /* lam = 1, 0 */
    for (int k = 0; k < 3; k++) {
        int l = (k + 1) % 3;
        double lam = (b[l] - b[k]) / ((a[k] - b[k]) - (a[l] - b[l]));
        if (lam > 0 && lam < 1) U = dmin(U, mixed(a, b, lam));
    }
    return U;
}

/* |p - a| <= sqrt(d2 (1 + 2^-50) + 2^-1070), d2 the computed square: each
 * difference is within a factor 1 + u of the exact one (exact when
 * subnormal), each square and the two additions add a factor 1 + u and
 * at most 2^-1075 each, (1 + u)^5 < 1 + 2^-50; every step rounded up.
 * Then d(p, t) <= d(a, t) + |p - a| <= hi + |p - a| (the triangle
 * inequality), the sum rounded up. */
double hd__m2m_carried_bound(double hi, const double a[3], const double p[3]) {
    double dx = p[0] - a[0], dy = p[1] - a[1], dz = p[2] - a[2];
    double d2 = dx * dx + dy * dy + dz * dz;
    if (!(d2 < INFINITY) || !(hi < INFINITY)) return INFINITY;
    return up(hi + sqrt_up(up(up(d2 * (1 + 0x1p-50)) + 0x1p-1070)));
}

/* Tang's bound with the triangle nearest (as the bounds tell) to the
 * centroid of s's computed corners (before the slack e), from s's list
 * or else the tree, when it is none of the corners' own: U if not
 * smaller.  Any triangle of Y
 * gives a bound (the top); where the corners lie at vertices of Y, each
 * nearest to one of the triangles around it, the one under the whole
 * sub-triangle need not be any corner's.  Tried from the tree at the
 * levels without lists only: deeper, a sub-triangle whose list could not
 * be collected has too many triangles near it for one to settle it
 * (bench/m2m_run, `shared`: its maximum lies on Y's medial axis). */
static double centre_bound(const hd__m2m_job_t *J, sub_t *s, double U, const uint32_t *arena, cache_t *C,
                           uint64_t *kernel) {
    const hd__bvh_t *T = J->to;
    double g[3], lo2, hi2, best = INFINITY;
    for (int d = 0; d < 3; d++) g[d] = (s->c[0].p[d] + s->c[1].p[d] + s->c[2].p[d]) / 3;
    size_t pos = SIZE_MAX;
    if (s->n != NO_LIST) {
        for (size_t i = 0; i < s->n; i++) {
            size_t k = arena[s->off + i];
            if (beyond(&T->boxes[k], g, best)) continue;
            bounds_at(T, k, g, C, &lo2, &hi2);
            (*kernel)++;
            if (pos == SIZE_MAX || hi2 < best) best = hi2, pos = k;
        }
    }
    if (pos == SIZE_MAX) {
        double lo, hi;
        pos = interval(T, g, s->c[0].pos, C, -1, &lo, &hi, kernel);
    }
    if (pos == SIZE_MAX || pos == s->c[0].pos || pos == s->c[1].pos || pos == s->c[2].pos) return U;
    double m = 0;
    for (int k = 0; k < 3 && m < U; k++) m = dmax(m, corner_to(&s->c[k], pos, &T->tris[pos], C, kernel));
    return dmin(U, m);
}

/* The sub-triangle's upper bound; once the point bound alone is at most
 * `enough` (the sub-triangle will be discarded whatever its bound) the
 * dearer bounds are skipped. */
static double upper_core(const hd__m2m_job_t *J, sub_t *s, double e, double enough, cache_t *C, uint64_t *kernel,
                         int centre, const uint32_t *arena) {
    double rmax = 0;
    for (int i = 0; i < 3; i++) rmax = dmax(rmax, s->c[i].hi);
    double U = up(rmax + reach(s));
    if ((s->level ? up(U + e) : U) <= enough) return s->level ? up(U + e) : U;
    cands_t K = {.n = 0};
    for (int i = 0; i < 3; i++) {
        int seen = 0;
        for (int j = 0; j < K.n; j++) seen |= K.pos[j] == s->c[i].pos;
        if (!seen) {
            K.pos[K.n] = s->c[i].pos;
            for (int k = 0; k < 3; k++) K.h[K.n][k] = NAN;
            K.n++;
        }
    }
    for (int i = 0; i < K.n; i++) { /* Tang's bound over the corners' nearest triangles */
        double m = 0;
        for (int k = 0; k < 3 && m < U; k++) m = dmax(m, cand_h(J, s, &K, i, k, C, kernel));
        U = dmin(U, m);
    }
    double E = s->level ? e : 0;
    /* three triangles (corners at vertices of Y): the centroid's first */
    if (centre && K.n == 3 && up(U + E) > enough) U = centre_bound(J, s, U, arena, C, kernel), centre = 0;
    if (K.n > 1 && up(U + E) > enough) U = pair_bound(J, s, U, C, kernel);
    for (int i = 0; i < K.n && up(U + E) > enough; i++) /* bent pairs */
        for (int j = i + 1; j < K.n; j++) {
            for (int k = 0; k < 3; k++) cand_h(J, s, &K, i, k, C, kernel), cand_h(J, s, &K, j, k, C, kernel);
            U = hd__m2m_bent_bound(K.h[i], K.h[j], U);
        }
    if (centre && up(U + E) > enough) U = centre_bound(J, s, U, arena, C, kernel);
    return s->level ? up(U + e) : U;
}

/* upper_core without the centroid's triangle (a face's first bound). */
static double upper_of(const hd__m2m_job_t *J, sub_t *s, double e, double enough, cache_t *C,
                       uint64_t *kernel) {
    return upper_core(J, s, e, enough, C, kernel, 0, NULL);
}

/* The bound at or below which a (sub-)triangle's point bound makes the
 * dearer bounds useless, for a lower bound `bar` that the search's lower
 * bound already reaches: the predicate's d, or else bar plus the
 * tolerance (a face or sub-triangle whose bound is within the tolerance
 * of the lower bound is never split). */
static double enough_for(const hd__m2m_job_t *J, double bar) {
    return isfinite(J->done_below) ? dmax(bar, J->done_below) : bar + J->tol;
}

/* ---- phase 1: every face's corners -------------------------------------- */

/* A corner of a face as phase 0 finds it. */
typedef struct found {
    double lo, hi, r, near[3];
    size_t pos, index;
    int exact;
    int complete; /* hi is the smallest the bounds give (no early stop) */
} found_t;

typedef struct ctx {
    const hd__m2m_job_t *job;
    face_t *faces;
    const uint64_t *order; /* the corners (3 f + j) in Morton order, in the low 32 bits */
    found_t *found;        /* by corner */
    size_t n_corners;
    cache_t *caches;       /* one per worker */
    size_t task0;          /* phase 1's first task (the predicate's rounds) */
    double bar;            /* phase 0's exact searches: corners with hi >= bar */
    /* Phase 0 in stages: 0 every corner searched in full; 1 the sample
     * (every stride-th corner of the order) in full; 2 the others, each
     * search stopping at a bound below L0 (the sample's best exact
     * distance) minus its face's reach, plus the tolerance */
    int stage;
    size_t stride;
    double L0;
    double *target;        /* stage 2: each face's corner_target (or NULL) */
    int some_done;         /* 0: no face is done before phase 2 (no shared
                            * face, no screen), so phases 0 and 1 read no
                            * face's flag */
} ctx_t;

/* Face f is done (shared, or screened) in phases 0 and 1. */
static int done_early(const ctx_t *C, size_t f) { return C->some_done && C->faces[f].done; }

#define CORNER(J, id) ((J)->from[(id) / 3].v[(id) % 3])

/* About the farthest a point of face t is from its nearest corner (the
 * longest edge over sqrt 3, unrounded: it only sets a target). */
static double face_reach(const hd__tri_t *t) {
    double a2 = 0;
    for (int i = 0; i < 3; i++) {
        const double *p = t->v[i], *q = t->v[(i + 1) % 3];
        double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
        a2 = dmax(a2, dx * dx + dy * dy + dz * dz);
    }
    return sqrt(a2) * 0.5774;
}

/* The same corner, bit for bit (inline: phase 0 asks at every corner). */
static int same_point(const double *p, const double *q) {
    uint64_t a[3], b[3];
    memcpy(a, p, sizeof a);
    memcpy(b, q, sizeof b);
    return ((a[0] ^ b[0]) | (a[1] ^ b[1]) | (a[2] ^ b[2])) == 0;
}

/* Corner k of the order is in stage 1's sample: every stride-th position
 * that starts a run of equal corners (a vertex of X and its copies). */
static int is_sample(const ctx_t *C, size_t k) {
    if (k % C->stride) return 0;
    if (k == 0) return 1;
    size_t id = C->order ? (size_t)(C->order[k] & 0xffffffffu) : k;
    size_t pr = C->order ? (size_t)(C->order[k - 1] & 0xffffffffu) : k - 1;
    return !same_point(CORNER(C->job, id), CORNER(C->job, pr));
}

/* Stage 2's target for corner id: a bound at most this puts the corner
 * below L0, so it needs no exact distance, and with its face's other
 * corners as low the face's point bound is within the tolerance of L0. */
static double corner_target(const ctx_t *C, size_t id) {
    if (C->target) return C->target[id / 3];
    const hd__m2m_job_t *J = C->job;
    return dmin(C->L0 + J->tol - face_reach(&J->from[id / 3]), down(C->L0));
}

/* Every face's stage-2 target at once (each face has three corners), in
 * C->target; left NULL without memory (then each corner computes it). */
static void corner_targets(ctx_t *C) {
    const hd__m2m_job_t *J = C->job;
    C->target = hd__malloc_array(J->n_from ? J->n_from : 1, sizeof *C->target);
    if (!C->target) return;
    double *t = C->target;
    C->target = NULL;
    for (size_t f = 0; f < J->n_from; f++) t[f] = done_early(C, f) ? 0 : corner_target(C, 3 * f);
    C->target = t;
}

/* Stage 2 without a search: the bound of corner id carried from an anchor
 * (the last corner of the chunk whose hi came from a search or the sample,
 * never a carried one, so that errors do not add up; d(anchor, triangle at
 * pos) <= hi) when it meets the corner's target: then hi >= d(corner,
 * triangle at pos) too (hd__m2m_carried_bound), which is all that phases 1
 * and 2 ask of a corner's hi and pos, and lo is 0.  1 when it does. */
static int carried(ctx_t *C, size_t anchor, size_t id, double target) {
    const found_t *A = &C->found[anchor];
    if (!(A->hi <= target)) return 0;
    const double *a = CORNER(C->job, anchor), *p = CORNER(C->job, id);
    double m = target - A->hi, dx = p[0] - a[0], dy = p[1] - a[1], dz = p[2] - a[2];
    if (dx * dx + dy * dy + dz * dz > m * m) return 0; /* a filter: the bound decides */
    double g = hd__m2m_carried_bound(A->hi, a, p);
    if (!(g <= target)) return 0;
    found_t *F = &C->found[id];
    F->lo = 0, F->hi = g, F->pos = A->pos, F->exact = 0, F->complete = 0;
    return 1;
}

/* Phase 0: each corner's distance enclosed (interval()), in Morton order
 * so that each search starts from its predecessor's answer; a corner equal
 * to its predecessor copies it (at stage 2 when that answer is complete or
 * meets the corner's own target). */
static void phase0(void *vctx, size_t task, int worker) {
    ctx_t *C = vctx;
    const hd__m2m_job_t *J = C->job;
    size_t lo = task * CHUNK * 3, hi = lo + CHUNK * 3 < C->n_corners ? lo + CHUNK * 3 : C->n_corners;
    size_t seed = SIZE_MAX, prev = SIZE_MAX, anchor = SIZE_MAX;
    uint64_t count = 0;
    /* stage 1 visits the sample's positions alone (multiples of the stride) */
    size_t step = C->stage == 1 ? C->stride : 1;
    for (size_t k = C->stage == 1 ? (lo + step - 1) / step * step : lo; k < hi; k += step) {
        size_t id = C->order ? (size_t)(C->order[k] & 0xffffffffu) : k;
        found_t *F = &C->found[id];
        if (done_early(C, id / 3)) continue;
        int sampled = C->stage && is_sample(C, k);
        if (C->stage == 1 && !sampled) continue;
        if (C->stage == 2 && sampled) { /* done at stage 1 */
            seed = F->pos, prev = anchor = id;
            continue;
        }
        int same = prev != SIZE_MAX && ((J->vertex && J->vertex[id] == J->vertex[prev]) ||
                                        same_point(CORNER(J, id), CORNER(J, prev)));
        if (same && C->found[prev].complete) {
            *F = C->found[prev];
            continue;
        }
        double target = C->stage == 2 ? corner_target(C, id) : -INFINITY;
        if (same && C->found[prev].hi <= target) {
            *F = C->found[prev];
            continue;
        }
        if (C->stage == 2 && anchor != SIZE_MAX && carried(C, anchor, id, target)) {
            prev = id;
            continue;
        }
        F->pos = seed =
            interval(J->to, CORNER(J, id), seed, &C->caches[worker], enough_of(target), &F->lo, &F->hi, &count);
        F->exact = 0;
        F->complete = !(F->hi <= target);
        prev = id;
        anchor = id;
    }
    C->faces[lo / 3].kernel += count; /* counted on the chunk's first face */
}

/* The corners (of C->order's first n_corners) that can be the largest:
 * those whose hi reaches the largest lo (every other one is nearer to Y
 * than that corner), or all of them when each face's own lower bound is
 * asked for. */
static double phase0_bar(const ctx_t *C) {
    const hd__m2m_job_t *J = C->job;
    if (J->per_face || J->face_lower) return -INFINITY;
    double bar = C->stage == 2 ? C->L0 : -INFINITY;
    if (C->stage != 1 && C->n_corners == 3 * J->n_from) { /* every corner: in id order, no indirection */
        for (size_t id = 0; id < C->n_corners; id++)
            if (!done_early(C, id / 3)) bar = dmax(bar, C->found[id].lo);
        return bar;
    }
    for (size_t k = 0; k < C->n_corners; k += C->stage == 1 ? C->stride : 1) {
        size_t id = C->order ? (size_t)(C->order[k] & 0xffffffffu) : k;
        if (!done_early(C, id / 3) && (C->stage != 1 || is_sample(C, k))) bar = dmax(bar, C->found[id].lo);
    }
    return bar;
}

/* Phase 0, second part: those corners' exact distances (through the tree:
 * the answer is the brute force's, it depends on the point alone). */
static void phase0_exact(void *vctx, size_t task, int worker) {
    (void)worker;
    ctx_t *C = vctx;
    const hd__m2m_job_t *J = C->job;
    size_t lo = task * CHUNK * 3, hi = lo + CHUNK * 3 < C->n_corners ? lo + CHUNK * 3 : C->n_corners;
    hd__bvh_stats_t st = {0};
    /* stage 1 visits the sample's positions alone (multiples of the stride) */
    size_t step = C->stage == 1 ? C->stride : 1;
    for (size_t k = C->stage == 1 ? (lo + step - 1) / step * step : lo; k < hi; k += step) {
        size_t id = C->order ? (size_t)(C->order[k] & 0xffffffffu) : k;
        found_t *F = &C->found[id];
        if (done_early(C, id / 3) || (C->stage == 1 && !is_sample(C, k)) || F->hi < C->bar) continue;
        if (C->stage == 2 && F->exact) continue; /* the sample's, at stage 1 */
        hd__tri_near_t near;
        F->pos = hd__bvh_nearest(J->to, CORNER(J, id), F->pos, 0, &near, &F->index, &st);
        F->r = near.d;
        F->hi = up(near.d);
        memcpy(F->near, near.point, sizeof F->near);
        F->exact = 1;
    }
    C->faces[lo / 3].kernel += st.kernel;
}

/* Face f's level-0 sub-triangle from its corners' nearest triangles x,
 * its corners offered as lower bounds, its bound (the dearer bounds
 * skipped once the point bound is at most `enough`). */
static void face_top(const hd__m2m_job_t *J, face_t *F, size_t f, const found_t *x, double enough, cache_t *cache) {
    for (int i = 0; i < 3; i++) {
        corner_t *c = &F->top.c[i];
        c->k[0] = c->k[1] = c->k[2] = 0;
        c->k[i] = 1;
        memcpy(c->p, J->from[f].v[i], sizeof c->p);
        c->r = c->lower = x[i].r;
        c->hi = x[i].hi;
        c->exact = x[i].exact;
        c->nm = 0;
        c->pos = x[i].pos;
        c->index = x[i].index;
        memcpy(c->near, x[i].near, sizeof c->near);
        if (c->exact) offer(&F->best, c, 0, 0);
    }
    F->top.level = 0;
    F->top.n = NO_LIST;
    F->top.off = 0;
    F->top.U = upper_of(J, &F->top, 0, enough, cache, &F->kernel);
    F->upper = F->top.U;
}

static void phase1(void *vctx, size_t task, int worker) {
    ctx_t *C = vctx;
    const hd__m2m_job_t *J = C->job;
    size_t lo = (C->task0 + task) * CHUNK, hi = lo + CHUNK < J->n_from ? lo + CHUNK : J->n_from;
    double enough = J->face_upper ? -INFINITY : enough_for(J, C->bar);
    for (size_t f = lo; f < hi; f++)
        if (!done_early(C, f)) face_top(J, &C->faces[f], f, &C->found[3 * f], enough, &C->caches[worker]);
}

/* ---- the predicate's pass: screen, then exact corners, in rounds --------- */

/* The screen's search gives up after bounding this many triangles. */
#define SCREEN_TRIS 24

/* An upper bound on d(p, Y) that is at most target, from prepared bounds
 * alone: 1 with *ub (and *seed its triangle's position), or 0.  Any
 * triangle's sqrt_up(hi2) is >= d(p, Y), so which triangles are tried (the
 * seed, then the tree nearest box first, pruned by plain box distances, at
 * most SCREEN_TRIS of them) changes the cost only, never the bound's
 * validity. */
static int screen_point(const hd__bvh_t *T, const double p[3], double target, size_t *seed, double *ub) {
    double lo2, hi2, t2 = target * target * (1 + 0x1p-40);
    if (*seed != SIZE_MAX) {
        hd__tri_bounds_prep(p, hd__bvh_prep(T, *seed), &lo2, &hi2);
        if (sqrt_up(hi2) <= target) return *ub = sqrt_up(hi2), 1;
    }
    uint32_t stack[128];
    int top = 0, tried = 0;
    stack[top++] = 0;
    while (top > 0) {
        uint32_t id = stack[--top];
        const hd__bvh_node_t *node = &T->nodes[id];
        if (node->count) {
            for (size_t k = node->first_or_second, end = k + node->count; k < end; k++) {
                if (k == *seed) continue;
                hd__tri_bounds_prep(p, hd__bvh_prep(T, k), &lo2, &hi2);
                if (lo2 > t2) continue;
                if (sqrt_up(hi2) <= target) return *seed = k, *ub = sqrt_up(hi2), 1;
                if (++tried >= SCREEN_TRIS) return 0;
            }
            continue;
        }
        uint32_t a = id + 1, b = node->first_or_second;
        double la = hd__box_lb2s(&T->nodes[a].box, p[0], p[1], p[2]);
        double lb = hd__box_lb2s(&T->nodes[b].box, p[0], p[1], p[2]);
        if (top + 2 > 128) return 0;
        if (la > lb) { /* the nearer child on top */
            if (la <= t2) stack[top++] = a;
            if (lb <= t2) stack[top++] = b;
        } else {
            if (lb <= t2) stack[top++] = b;
            if (la <= t2) stack[top++] = a;
        }
    }
    return 0;
}

/* Tang's bound with one triangle of Y (position pos): d(., t) is convex,
 * so over the face it is at most its largest value at a vertex. */
static int tang_screened(const hd__m2m_job_t *J, const hd__tri_t *t, size_t pos, double *upper) {
    double m = 0, lo2, hi2;
    for (int i = 0; i < 3 && m <= J->done_below; i++) {
        hd__tri_bounds_prep(t->v[i], hd__bvh_prep(J->to, pos), &lo2, &hi2);
        m = dmax(m, sqrt_up(hi2));
    }
    if (!(m <= J->done_below)) return 0;
    *upper = m;
    return 1;
}

/* Face t discarded by the predicate's d without the kernel: the point
 * bound over its exact corners, d(y, Y) <= max_v ub_v + R for every y of
 * the face (e = 0 at level 0), is at most d; or else Tang's bound with the
 * last triangle the screen found.  1 with that bound in *upper. */
static int screened(const hd__m2m_job_t *J, const hd__tri_t *t, size_t *seed, double *upper) {
    sub_t s;
    for (int i = 0; i < 3; i++) memcpy(s.c[i].p, t->v[i], sizeof s.c[i].p);
    double R = reach(&s), target = J->done_below - R, m = 0, ub;
    int i = 0;
    if (target >= 0)
        for (; i < 3 && screen_point(J->to, t->v[i], target, seed, &ub); i++) m = dmax(m, ub);
    double U = up(m + R);
    if (i == 3 && U <= J->done_below) {
        *upper = U;
        return 1;
    }
    return *seed != SIZE_MAX && tang_screened(J, t, *seed, upper);
}

/* The predicate's screen over one task of faces of the round. */
static void screen_task(void *vctx, size_t task, int worker) {
    (void)worker;
    ctx_t *C = vctx;
    const hd__m2m_job_t *J = C->job;
    size_t lo = (C->task0 + task) * CHUNK, hi = lo + CHUNK < J->n_from ? lo + CHUNK : J->n_from;
    size_t seed = SIZE_MAX;
    for (size_t f = lo; f < hi; f++)
        if (!C->faces[f].done && screened(J, &J->from[f], &seed, &C->faces[f].upper)) C->faces[f].done = 1;
}

/* The corners of the faces not dropped (J->drop), in *out (their ids in
 * the low 32 bits) and their number in *count: the vertices of X those
 * corners use in Morton order (a key per vertex, not per corner), each
 * vertex's corners together in increasing id, so that equal corners
 * follow each other; NULL when there are too many corners or no vertex
 * indices (then every corner in index order; any order is correct).  A
 * dropped face's corners are never searched, so they take no place in
 * the order and no part in its grid (bench/m2m_run, `shared`). */
static int corner_order(const hd__m2m_job_t *J, int threads, uint64_t **out, size_t *count) {
    *out = NULL;
    size_t n = 3 * J->n_from, nv = J->n_vertices, m = 0, live = 0;
    *count = n;
    if (n > UINT32_MAX || !J->vertex) return HD_OK;
    uint32_t *first = hd__malloc_array(nv ? nv : 1, sizeof *first); /* a corner of each vertex used */
    size_t *at = hd__malloc_array(nv ? nv : 1, sizeof *at);
    uint64_t *keys = hd__malloc_array(nv ? nv : 1, sizeof *keys), *tmp = hd__malloc_array(nv ? nv : 1, sizeof *tmp);
    uint64_t *order = hd__malloc_array(n ? n : 1, sizeof *order);
    int rc = first && at && keys && tmp && order ? HD_OK : HD_ENOMEM;
    hd__box_t box = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    for (size_t v = 0; rc == HD_OK && v < nv; v++) first[v] = UINT32_MAX, at[v] = 0;
    for (size_t id = 0; rc == HD_OK && id < n; id++) {
        if (J->drop && J->drop[id / 3]) continue;
        uint32_t v = J->vertex[id];
        at[v]++, live++;
        if (first[v] != UINT32_MAX) continue;
        first[v] = (uint32_t)id;
        const double *p = CORNER(J, id);
        for (int d = 0; d < 3; d++) box.lo[d] = dmin(box.lo[d], p[d]), box.hi[d] = dmax(box.hi[d], p[d]);
    }
    if (rc == HD_OK) {
        hd__keygrid_t g;
        hd__keygrid_init(&g, &box);
        for (size_t v = 0; v < nv; v++)
            if (first[v] != UINT32_MAX) keys[m++] = (uint64_t)hd__key30(&g, CORNER(J, first[v])) << 32 | (uint64_t)v;
        rc = m ? hd__radix_sort(&keys, &tmp, m, threads) : HD_OK;
    }
    if (rc == HD_OK) {
        size_t next = 0; /* each vertex's first place in the order */
        for (size_t i = 0; i < m; i++) {
            size_t v = (size_t)(keys[i] & 0xffffffffu), c = at[v];
            at[v] = next, next += c;
        }
        for (size_t id = 0; id < n; id++)
            if (!(J->drop && J->drop[id / 3])) order[at[J->vertex[id]]++] = (uint64_t)id;
        *out = order, *count = live;
    }
    free(first), free(at), free(keys), free(tmp);
    if (rc) free(order);
    return rc;
}

/* ---- phase 2: refining one face ----------------------------------------- */

/* A worker's sub-triangles: a pool with a free list, ordered by a heap. */
typedef struct pool {
    sub_t *s;
    size_t n, cap;
    size_t *free_;
    size_t n_free;
    hd__heap_t heap;
    cache_t *cache;
    int failed;
    /* the candidate lists of the sub-triangles of the face being refined
     * (sub_t.off, n index it; emptied at each visit) */
    uint32_t *arena;
    size_t a_n, a_cap;
} pool_t;

static size_t pool_put(pool_t *P, const sub_t *s) {
    size_t k;
    if (P->n_free) {
        k = P->free_[--P->n_free];
    } else {
        if (P->n == P->cap) {
            size_t cap = P->cap ? 2 * P->cap : 64;
            sub_t *ns = realloc(P->s, cap * sizeof *ns);
            size_t *nf = realloc(P->free_, cap * sizeof *nf);
            if (ns) P->s = ns;
            if (nf) P->free_ = nf;
            if (!ns || !nf) {
                P->failed = 1;
                return SIZE_MAX;
            }
            P->cap = cap;
        }
        k = P->n++;
    }
    P->s[k] = *s;
    if (hd__heap_push(&P->heap, s->U, k)) {
        P->failed = 1;
        return SIZE_MAX;
    }
    return k;
}

/* The four children of s (corners 0, 1, 2; midpoints m01, m12, m20). */
static double threshold(const hd__m2m_job_t *J, double L, const face_t *F) {
    double thr = J->per_face ? F->best.lower : dmax(L, F->best.lower);
    return thr;
}

/* A point whose could() is at most this cannot change the result: the
 * face's own best, and L unless each face's own lower bound is asked for. */
static double exact_bar(const hd__m2m_job_t *J, double L, const face_t *F) {
    double own = F->best.set ? F->best.lower : -INFINITY;
    return J->per_face || J->face_lower ? own : dmax(L, own);
}

/* ---- candidate lists ---------------------------------------------------- */

/* Box b certainly farther than sqrt(r2) from box a: the computed
 * hd__box_box_lb2 is at most the exact squared gap times (1 + u)^5 (one
 * rounding a difference, exact when not normal, one a square, two sums)
 * when it is at least 2^-1000, where underflow's 2^-1074 an operation is
 * below a relative 2^-70; s (1 - 2^-46), rounded, is then below the exact
 * square. */
static int box_far(const hd__box_t *a, const hd__box_t *b, double r2) {
    double s = hd__box_box_lb2(a, b);
    return s >= 0x1p-1000 && s * (1 - 0x1p-46) > r2;
}

/* The box of the computed corners c widened by 2e on each side, rounded
 * outward, and r2 >= H^2 with H = up(U + 2e) (hd__m2m_candidates). */
static void cand_region(const double c[3][3], double U, double e, hd__box_t *B, double *r2) {
    double w = up(2 * e);
    for (int k = 0; k < 3; k++) {
        double lo = dmin(c[0][k], dmin(c[1][k], c[2][k])), hi = dmax(c[0][k], dmax(c[1][k], c[2][k]));
        B->lo[k] = down(lo - w);
        B->hi[k] = up(hi + w);
    }
    double H = up(U + w);
    *r2 = up(H * H);
}

size_t hd__m2m_candidates(const hd__bvh_t *T, const double c[3][3], double U, double e, const uint32_t *from,
                          size_t n_from, uint32_t *out, size_t cap) {
    hd__box_t B;
    double r2;
    cand_region(c, U, e, &B, &r2);
    if (!from) return hd__bvh_collect(T, &B, r2, out, cap);
    size_t n = 0;
    for (size_t i = 0; i < n_from; i++) {
        if (box_far(&T->boxes[from[i]], &B, r2)) continue;
        if (n == cap) return SIZE_MAX;
        out[n++] = from[i];
    }
    return n;
}

/* Most entries a worker's arena holds, and most a list collected from the
 * tree may have (beyond them the tree is searched instead). */
#define ARENA_MAX ((size_t)1 << 24)
#define LIST_MAX 48
/* A sub-triangle without a list whose collection failed (too many
 * candidates) lets its descendants try again RETRY levels down. */
#define RETRY 2
/* Lists are collected from the tree from this level on: a shallower
 * sub-triangle is often split once only (each face of a finer X over a
 * coarser Y), and one box query then costs as much as the point searches
 * it would replace (bench/m2m_bench.py's `subdivided` and `decimated`;
 * `nearzero` splits deep, where inherited lists pay). */
#define LIST_LEVEL 2

/* s's own candidate list in P's arena (s->off, s->n), from the one it
 * inherited or else from the tree; s->n = NO_LIST when there is none
 * (then s->off is the level from which its descendants try again). */
static void own_list(const hd__m2m_job_t *J, double e, sub_t *s, pool_t *P) {
    size_t need = s->n != NO_LIST ? s->n : LIST_MAX;
    if (s->n == NO_LIST && ((uint32_t)s->level < s->off || s->level < LIST_LEVEL)) return;
    if (P->a_n + need > ARENA_MAX) {
        s->n = NO_LIST, s->off = UINT32_MAX;
        return;
    }
    if (P->a_n + need > P->a_cap) {
        size_t cap = P->a_cap ? P->a_cap : 4096;
        while (cap < P->a_n + need) cap *= 2;
        uint32_t *na = realloc(P->arena, cap * sizeof *na);
        if (!na) {
            s->n = NO_LIST, s->off = UINT32_MAX;
            return;
        }
        P->arena = na, P->a_cap = cap;
    }
    double c[3][3];
    for (int i = 0; i < 3; i++) memcpy(c[i], s->c[i].p, sizeof c[i]);
    const uint32_t *from = s->n != NO_LIST ? P->arena + s->off : NULL;
    size_t n = hd__m2m_candidates(J->to, c, s->U, e, from, s->n != NO_LIST ? s->n : 0, P->arena + P->a_n, need);
    if (n == SIZE_MAX) {
        s->n = NO_LIST, s->off = (uint32_t)s->level + RETRY;
        return;
    }
    s->off = (uint32_t)P->a_n, s->n = (uint32_t)n;
    P->a_n += n;
}

static void split(const hd__m2m_job_t *J, const hd__tri_t *t, double e, double L, const sub_t *s, sub_t kids[4],
                  face_t *F, pool_t *P, hd__bvh_stats_t *st) {
    int level = s->level + 1;
    corner_t c[3], m[3];
    for (int i = 0; i < 3; i++) {
        c[i] = s->c[i];
        for (int j = 0; j < 3; j++) c[i].k[j] = 2 * s->c[i].k[j];
    }
    /* A midpoint bounded by at most `target` needs no tighter bound: it
     * cannot raise a lower bound (target <= exact_bar), and its own bound,
     * plus e, is at most max(the threshold + tolerance, d), where a
     * sub-triangle is never split, so it raises none of its children's
     * Tang bounds above that (those with other triangles take its distance
     * to each afresh, corner_to); the triangle it names may be a
     * poorer candidate for their Tang bounds than its nearest, which
     * centre_bound makes up for (bench/m2m_run, `nearzero`,
     * `subdivided`). */
    double target = dmin(dmax(threshold(J, L, F) + J->tol, J->done_below) - 2 * e, exact_bar(J, L, F));
    for (int i = 0; i < 3; i++) {
        const corner_t *p = &s->c[i], *q = &s->c[(i + 1) % 3];
        for (int j = 0; j < 3; j++) m[i].k[j] = p->k[j] + q->k[j];
        m[i].nm = 0;
        if (s->n != NO_LIST)
            evaluate_in(J, t, &m[i], level, p->pos, target, P->arena + s->off, s->n, P->cache, &F->kernel);
        else
            evaluate(J, t, &m[i], level, p->pos, target, P->cache, &F->kernel);
        if (could(&m[i], level, e) > exact_bar(J, L, F)) {
            make_exact(J, &m[i], level, e, st);
            offer(&F->best, &m[i], level, e);
        }
    }
    corner_t *tri[4][3] = {{&c[0], &m[0], &m[2]}, {&m[0], &c[1], &m[1]}, {&m[2], &m[1], &c[2]},
                           {&m[0], &m[1], &m[2]}};
    double enough = enough_for(J, threshold(J, L, F));
    /* the corners' remembered bounds go back to c and m after each child,
     * so that its siblings (and, copied again below, its descendants)
     * reuse them */
    for (int q = 0; q < 4; q++) {
        for (int i = 0; i < 3; i++) kids[q].c[i] = *tri[q][i];
        kids[q].level = level;
        kids[q].off = s->off, kids[q].n = s->n;
        int centre = kids[q].n != NO_LIST || level < LIST_LEVEL;
        kids[q].U = upper_core(J, &kids[q], e, enough, P->cache, &F->kernel, centre, P->arena);
        for (int i = 0; i < 3; i++) *tri[q][i] = kids[q].c[i];
    }
    for (int q = 0; q < 3; q++)
        for (int i = 0; i < 3; i++) kids[q].c[i] = *tri[q][i];
}

/* Keep what is left of a face's heap for its next visit (F->upper: its
 * bound now).  0, or -1 out of memory. */
static int save(face_t *F, pool_t *P, double cut) {
    F->n_saved = hd__heap_size(&P->heap);
    F->saved = hd__malloc_array(F->n_saved, sizeof *F->saved);
    if (!F->saved) return P->failed = 1, -1;
    F->upper = dmax(hd__heap_top(&P->heap)->key, cut);
    F->cut = cut;
    for (size_t k = 0; k < F->n_saved; k++) {
        F->saved[k] = P->s[hd__heap_pop(&P->heap).val];
        F->saved[k].n = NO_LIST; /* the arena is emptied at the next visit */
        F->saved[k].off = 0;
    }
    return 0;
}

/* Refine face f against the lower bound L of the batches before it, from
 * where its last visit stopped, for at most `budget` splits: then the face
 * is left pending (saved) with its bound so far, else it is done. */
static void refine(const hd__m2m_job_t *J, face_t *F, size_t f, double L, pool_t *P, uint64_t budget) {
    const hd__tri_t *t = &J->from[f];
    double e = slack(t), cut = F->cut; /* cut: the largest U discarded */
    hd__bvh_stats_t st = {0};
    hd__heap_clear(&P->heap);
    P->n = P->n_free = 0;
    P->a_n = 0;
    if (!F->saved && pool_put(P, &F->top) == SIZE_MAX) return;
    for (size_t k = 0; k < F->n_saved; k++)
        if (pool_put(P, &F->saved[k]) == SIZE_MAX) return;
    free(F->saved);
    F->saved = NULL;
    F->n_saved = 0;
    for (uint64_t visit = 0;; visit++) {
        if (hd__heap_size(&P->heap) == 0) {
            F->upper = cut;
            break;
        }
        const hd__heap_item_t *top = hd__heap_top(&P->heap);
        double thr = threshold(J, L, F);
        if (top->key - thr <= J->tol || top->key <= J->done_below || F->best.lower > J->stop_above) {
            F->upper = dmax(top->key, cut);
            break;
        }
        if (visit == budget) {
            F->kernel += st.kernel;
            save(F, P, cut);
            return;
        }
        hd__heap_item_t it = hd__heap_pop(&P->heap);
        sub_t s = P->s[it.val];
        P->free_[P->n_free++] = (size_t)it.val;
        if (s.level >= MAX_LEVEL || (J->max_splits && F->splits >= J->max_splits)) {
            F->capped = 1;
            if (s.level >= MAX_LEVEL) {
                cut = dmax(cut, s.U);
                continue;
            }
            F->upper = dmax(s.U, cut);
            break;
        }
        sub_t kids[4];
        own_list(J, e, &s, P);
        split(J, t, e, L, &s, kids, F, P, &st);
        F->splits++;
        thr = threshold(J, L, F);
        for (int q = 0; q < 4; q++) {
            if (kids[q].U <= dmax(thr, J->done_below)) cut = dmax(cut, kids[q].U);
            else if (pool_put(P, &kids[q]) == SIZE_MAX) return;
        }
    }
    F->kernel += st.kernel;
    F->done = 1;
}

typedef struct batch {
    ctx_t *C;
    const size_t *order;
    double L;
    pool_t *pools;
    uint64_t budget;
} batch_t;

static void phase2(void *vctx, size_t task, int worker) {
    batch_t *B = vctx;
    size_t f = B->order[task];
    pool_t *P = &B->pools[worker];
    if (!P->failed) refine(B->C->job, &B->C->faces[f], f, B->L, P, B->budget);
}

/* ---- the whole search ---------------------------------------------------- */

typedef struct rank {
    double U;
    size_t f;
} rank_t;

static int by_upper(const void *x, const void *y) {
    const rank_t *a = x, *b = y;
    if (a->U != b->U) return a->U > b->U ? -1 : 1;
    return (a->f > b->f) - (a->f < b->f);
}

/* U's part of a rank's sort key: the complement of U's bits (U > 0;
 * else the largest key). */
static uint64_t u_key(const rank_t *r) {
    uint64_t key;
    memcpy(&key, &r->U, sizeof key);
    return r->U > 0 ? ~key : ~(uint64_t)0;
}

/* Digit `pass` of a rank's sort key: passes 0-7 the bytes of f, 8-15
 * those of u_key. */
static unsigned rank_digit(const rank_t *r, int pass) {
    if (pass < 8) return (unsigned)(((uint64_t)r->f >> (8 * pass)) & 255);
    return (unsigned)((u_key(r) >> (8 * (pass - 8))) & 255);
}

/* rk sorted as by_upper sorts it (by decreasing U, then increasing f):
 * a stable radix sort, by f and then by U's bits (for U >= 0 their order
 * as unsigned integers is U's), eight bits a pass, passes whose digit is
 * the same for every entry skipped; qsort when no scratch is free. */
static void sort_ranks(rank_t *rk, size_t n) {
    rank_t *tmp = n > 1 ? hd__malloc_array(n, sizeof *tmp) : NULL;
    if (!tmp) {
        qsort(rk, n, sizeof *rk, by_upper);
        return;
    }
    rank_t *src = rk, *dst = tmp;
    size_t (*count)[256] = calloc(16, sizeof *count); /* every digit's histogram, in one read */
    if (!count) {
        free(tmp);
        qsort(rk, n, sizeof *rk, by_upper);
        return;
    }
    /* entries already in increasing f (phase 1's ranks) need only the
     * passes by U: a stable sort keeps that order among equal U */
    int first = 8;
    for (size_t k = 1; k < n && first == 8; k++) first = rk[k - 1].f < rk[k].f ? 8 : 0;
    for (size_t k = 0; k < n; k++) {
        uint64_t f = (uint64_t)rk[k].f, u = u_key(&rk[k]);
        for (int b = 0; b < 8; b++) count[8 + b][(u >> (8 * b)) & 255]++;
        if (!first)
            for (int b = 0; b < 8; b++) count[b][(f >> (8 * b)) & 255]++;
    }
    for (int pass = first; pass < 16; pass++) {
        size_t at = 0, same = 0;
        for (int d = 0; d < 256; d++) {
            same |= count[pass][d] == n;
            at += count[pass][d];
            count[pass][d] = at - count[pass][d];
        }
        if (same) continue;
        for (size_t k = 0; k < n; k++) dst[count[pass][rank_digit(&src[k], pass)]++] = src[k];
        rank_t *t = src;
        src = dst, dst = t;
    }
    if (src != rk) memcpy(rk, src, n * sizeof *rk);
    free(tmp);
    free(count);
}

static void take_best(hd__m2m_result_t *R, const face_t *F, size_t f) {
    if (!F->best.set) return;
    if (R->face != SIZE_MAX && !(F->best.lower > R->lower)) return;
    const corner_t *c = &F->best.c;
    R->lower = F->best.lower;
    R->face = f;
    for (int j = 0; j < 3; j++) R->bary[j] = ldexp((double)c->k[j], -F->best.level);
    memcpy(R->point, c->p, sizeof R->point);
    R->witness_distance = c->r;
    R->witness_error = F->best.e;
    R->face_b = c->index;
    memcpy(R->point_b, c->near, sizeof R->point_b);
}

static void finish_face(hd__m2m_result_t *R, const hd__m2m_job_t *J, const face_t *F, size_t f) {
    if (J->face_lower) J->face_lower[f] = F->best.set ? F->best.lower : 0;
    if (J->face_upper) J->face_upper[f] = F->upper;
    R->upper = dmax(R->upper, F->upper);
    R->splits += F->splits;
    R->kernel_calls += F->kernel;
    R->capped |= F->capped;
}

/* A face whose bound can still exceed the lower bound L by more than the
 * tolerance (and the predicate's d).  L only grows and a face's bound
 * changes only when it is visited, so a face not pending when phase 2
 * starts is never pending: it is left out of the ranks, which changes no
 * batch (a face not pending takes no place in one). */
static int pending(const hd__m2m_job_t *J, const face_t *F, double L) {
    return F->upper - L > J->tol && F->upper > J->done_below;
}

/* One pass over the faces rk[0, n) (by decreasing bound) in batches of
 * growing size, each face visited for at most B->budget splits. */
static int pass(const hd__m2m_job_t *J, ctx_t *C, const rank_t *rk, size_t n, batch_t *B, size_t *size,
                hd__m2m_result_t *R) {
    size_t next = 0, *order = (size_t *)B->order;
    while (next < n) {
        if (R->lower > J->stop_above) break; /* the predicate is answered */
        size_t m = 0;
        /* faces whose bound cannot exceed L (or the predicate's d) are finished */
        for (; next < n && m < *size; next++) {
            face_t *F = &C->faces[rk[next].f];
            if (J->per_face || pending(J, F, R->lower)) {
                order[m++] = rk[next].f;
            } else { /* finished at its bound so far */
                free(F->saved);
                F->saved = NULL;
            }
        }
        B->L = J->per_face ? -INFINITY : R->lower;
        hd__parallel_for(J->threads, m, phase2, B);
        for (int w = 0; w < J->threads; w++)
            if (B->pools[w].failed) return HD_ENOMEM;
        for (size_t k = 0; k < m; k++) take_best(R, &C->faces[order[k]], order[k]);
        if (*size < MAX_BATCH) *size *= 2;
    }
    return HD_OK;
}

/* Phase 2: passes over the faces, the first visiting each face for
 * FIRST_BUDGET splits, each next one the faces left pending, by their
 * bounds so far, for four times as many.  A face whose maximum lies just
 * below the lower bound L of its batch needs every sub-triangle along that
 * maximum refined until its bound drops below L: against a stale L (a
 * face with a higher maximum still waiting in a later batch) that is
 * unbounded work, so no face is refined to the end before the faces with
 * higher bounds have had their turn. */
#define FIRST_BUDGET 64
static int run_batches(const hd__m2m_job_t *J, ctx_t *C, rank_t *rk, size_t n, hd__m2m_result_t *R) {
    pool_t *pools = calloc((size_t)J->threads, sizeof *pools);
    size_t *order = hd__malloc_array(MAX_BATCH, sizeof *order), size = FIRST_BATCH;
    int rc = pools && order ? HD_OK : HD_ENOMEM;
    for (int w = 0; pools && w < J->threads; w++) {
        hd__heap_init(&pools[w].heap, 1);
        pools[w].cache = &C->caches[w];
    }
    batch_t B = {C, order, 0, pools, FIRST_BUDGET};
    while (rc == HD_OK && n > 0) {
        rc = pass(J, C, rk, n, &B, &size, R);
        size_t m = 0;
        for (size_t k = 0; k < n; k++)
            if (C->faces[rk[k].f].saved) rk[m++] = (rank_t){C->faces[rk[k].f].upper, rk[k].f};
        sort_ranks(rk, m);
        n = R->lower > J->stop_above ? 0 : m;
        B.budget = B.budget < ((uint64_t)1 << 40) ? 4 * B.budget : B.budget;
    }
    for (size_t f = 0; f < J->n_from; f++) { /* pending faces keep their bound so far */
        free(C->faces[f].saved);
        C->faces[f].saved = NULL;
    }
    for (int w = 0; pools && w < J->threads; w++) {
        free(pools[w].s);
        free(pools[w].free_);
        free(pools[w].arena);
        hd__heap_free(&pools[w].heap);
    }
    free(pools);
    free(order);
    return rc;
}

/* The sample's largest exact distance (its corners are vertices of X, so
 * a lower bound with a witness), or -infinity. */
static double sample_best(const ctx_t *C) {
    double best = -INFINITY;
    for (size_t k = 0; k < C->n_corners; k += C->stride) {
        size_t id = C->order ? (size_t)(C->order[k] & 0xffffffffu) : k;
        if (!done_early(C, id / 3) && is_sample(C, k) && C->found[id].exact) best = dmax(best, C->found[id].r);
    }
    return best;
}

/* The first pass of a search for h: every face's corners, in Morton
 * order (phase 0), then every face's level-0 bound (phase 1). */
static int first_pass(const hd__m2m_job_t *J, ctx_t *C, hd__m2m_result_t *R) {
    size_t n = J->n_from;
    uint64_t *order = NULL;
    C->found = hd__malloc_array(n ? 3 * n : 1, sizeof *C->found);
    if (!C->found || corner_order(J, J->threads, &order, &C->n_corners)) {
        free(C->found);
        return HD_ENOMEM;
    }
    C->order = order;
    while (C->stride < MAX_STRIDE && C->n_corners / C->stride > SAMPLE_SIZE) C->stride *= 2;
    size_t tasks = (n + CHUNK - 1) / CHUNK, corner_tasks = (C->n_corners + 3 * CHUNK - 1) / (3 * CHUNK);
    if (!J->per_face && !J->face_lower) { /* the sample first: L0 */
        C->stage = 1;
        hd__parallel_for(J->threads, corner_tasks, phase0, C);
        C->bar = phase0_bar(C);
        hd__parallel_for(J->threads, corner_tasks, phase0_exact, C);
        C->L0 = sample_best(C);
        C->stage = isfinite(C->L0) ? 2 : 0;
        if (C->stage == 2) corner_targets(C);
    }
    hd__parallel_for(J->threads, corner_tasks, phase0, C);
    C->bar = phase0_bar(C);
    hd__parallel_for(J->threads, corner_tasks, phase0_exact, C);
    hd__parallel_for(J->threads, tasks, phase1, C);
    free(C->target);
    C->target = NULL;
    free(order);
    free(C->found);
    for (size_t f = 0; f < n; f++) take_best(R, &C->faces[f], f);
    return HD_OK;
}

/* The first pass of the predicate: rounds of faces (tasks of CHUNK faces,
 * FIRST_ROUND of them, then 8 times more each round, whatever the thread
 * count: few rounds, so that each round's corners share searches).  In
 * a round the faces are screened, the corners of the others measured in
 * Morton order (phase 0 over the round's part of the order) and their
 * level-0 bounds taken (phase 1); then the round's lower bounds are taken
 * in face order, and one above d stops the pass.  *stopped: 1 when it
 * stopped before the last face (faces never reached have no bound). */
#define FIRST_ROUND 2
static int decide_pass(const hd__m2m_job_t *J, ctx_t *C, hd__m2m_result_t *R, int *stopped) {
    size_t n = J->n_from, tasks = (n + CHUNK - 1) / CHUNK, size = FIRST_ROUND;
    uint64_t *order = NULL, *part = NULL;
    C->found = hd__malloc_array(n ? 3 * n : 1, sizeof *C->found);
    part = hd__malloc_array(n ? 3 * n : 1, sizeof *part);
    size_t live = 0;
    if (!C->found || !part || corner_order(J, J->threads, &order, &live)) {
        free(C->found);
        free(part);
        return HD_ENOMEM;
    }
    *stopped = 0;
    for (size_t t0 = 0; t0 < tasks; t0 += size, size *= 8) {
        size_t m = tasks - t0 < size ? tasks - t0 : size, f0 = t0 * CHUNK;
        size_t f1 = (t0 + m) * CHUNK < n ? (t0 + m) * CHUNK : n, k = 0;
        C->task0 = t0;
        hd__parallel_for(J->threads, m, screen_task, C);
        for (size_t i = 0; i < live; i++) {
            size_t id = order ? (size_t)(order[i] & 0xffffffffu) : i;
            if (id / 3 >= f0 && id / 3 < f1 && !C->faces[id / 3].done) part[k++] = id;
        }
        C->order = part;
        C->n_corners = k;
        hd__parallel_for(J->threads, (k + 3 * CHUNK - 1) / (3 * CHUNK), phase0, C);
        C->bar = phase0_bar(C);
        hd__parallel_for(J->threads, (k + 3 * CHUNK - 1) / (3 * CHUNK), phase0_exact, C);
        hd__parallel_for(J->threads, m, phase1, C);
        for (size_t f = f0; f < f1; f++) take_best(R, &C->faces[f], f);
        if (R->lower > J->stop_above && f1 < n) {
            *stopped = 1;
            break;
        }
    }
    free(order);
    free(part);
    free(C->found);
    return HD_OK;
}

int hd__m2m_run(const hd__m2m_job_t *J, hd__m2m_result_t *R) {
    memset(R, 0, sizeof *R);
    R->face = R->face_b = SIZE_MAX;
    size_t n = J->n_from;
    /* every face's state zero (calloc: no pass writing the zeros) */
    ctx_t C = {J, hd__calloc_array(n ? n : 1, sizeof(face_t)), NULL, NULL, 0, NULL, 0, 0, 0, SAMPLE_STRIDE, 0, NULL, 0};
    rank_t *rk = hd__malloc_array(n ? n : 1, sizeof *rk);
    C.n_corners = 3 * n;
    C.caches = caches_new(J->threads, J->to->n_tris);
    if (!C.faces || !rk || !C.caches) {
        free(C.faces);
        free(rk);
        caches_free(C.caches, J->threads);
        return HD_ENOMEM;
    }
    for (size_t f = 0; J->drop && f < n; f++) {
        C.faces[f].done = J->drop[f] != 0;
        R->dropped += C.faces[f].done;
    }
    /* the predicate (a finite d, faces not asked for one by one) */
    int decide = isfinite(J->done_below) && !J->per_face, stopped = 0;
    C.some_done = R->dropped > 0 || decide;
    int rc = decide ? decide_pass(J, &C, R, &stopped) : first_pass(J, &C, R);
    /* no face with a corner measured (every face shared, or screened):
     * 0 is a lower bound without a witness */
    if (R->face == SIZE_MAX) R->lower = 0;
    size_t live = 0;
    for (size_t f = 0; rc == HD_OK && f < n; f++)
        if (!C.faces[f].done && (J->per_face || pending(J, &C.faces[f], R->lower)))
            rk[live++] = (rank_t){C.faces[f].top.U, f};
    sort_ranks(rk, live);
    if (rc == HD_OK && !stopped) rc = run_batches(J, &C, rk, live, R);
    for (size_t f = 0; f < n; f++) finish_face(R, J, &C.faces[f], f);
    R->upper = stopped ? INFINITY : dmax(R->upper, R->lower);
    free(C.faces);
    caches_free(C.caches, J->threads);
    free(rk);
    return rc;
}
