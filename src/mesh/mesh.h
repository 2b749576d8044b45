/*
 * mesh.h -- the surface layer's front header (src/mesh/): the distance from
 * a point to a triangle, correctly rounded.
 *
 * The kernel's one promise: hd__tri_nearest() returns in `d` the true
 * Euclidean distance from p to the closed triangle abc (the convex hull of
 * its three corners, so a degenerate triangle is the segment or the point it
 * collapses to), rounded to the nearest double, ties to even.  Two calls on
 * the same doubles return the same bits on every machine with IEEE double
 * arithmetic, whatever the thread or the order of calls, so a search that
 * keeps the smallest `d` with the smallest triangle index is bit-identical
 * to a brute force over every triangle.  Rounding is monotone, so the
 * rounded distance to a mesh is the smallest rounded distance to its
 * triangles.
 *
 * How (tri.c has the proofs): the nearest feature (a corner, an edge or the
 * face) is the face when the projection's three weights are certainly
 * positive, else chosen by Ericson's Voronoi-region tests evaluated in
 * doubles, each sign accepted only when it exceeds a proven bound on its
 * rounding error; the squared distance N/M of that feature is evaluated as
 * compensated sums of products (double-double accuracy) with one a-priori
 * error bound per quantity; and the rounding of sqrt(N/M) is decided by one
 * Newton step with a proven error bound, or failing that by the signs of
 * N - m^2 M at the midpoints m around the candidate.  The same bits come
 * from the Dekker and the fused multiply-add products the kernel picks
 * between at run time.  When any of these signs is not certain (a point on
 * a region's boundary, a degenerate or nearly degenerate triangle, a
 * distance within about 2^-90 of a midpoint, coordinates far apart in
 * scale), the same questions are answered in exact integer arithmetic
 * (exact.c): every double is an integer times a power of two.
 *
 * The closest point and the barycentric weights are computed in doubles from
 * the exact feature: they are the point of that feature nearest to p up to a
 * few rounding errors, not correctly rounded.
 *
 * Domain: every coordinate finite with magnitude at most 2^511 (the library
 * validates points to 1e153); outside it the call returns HD_ERANGE.
 * Thread safety: none needed; the call reads its arguments and writes *out.
 */
#ifndef HD_MESH_H
#define HD_MESH_H

#include "base/base.h"
#include "points/points.h"

/* The feature of the triangle that holds the closest point. */
typedef enum hd__tri_feature {
    HD__TRI_FACE = 0,
    HD__TRI_EDGE_AB, HD__TRI_EDGE_BC, HD__TRI_EDGE_CA,
    HD__TRI_VERTEX_A, HD__TRI_VERTEX_B, HD__TRI_VERTEX_C
} hd__tri_feature_t;

typedef struct hd__tri_near {
    double d;                 /* the distance, correctly rounded */
    double point[3];          /* the closest point (see above) */
    double bary[3];           /* its weights of a, b and c, summing to about 1 */
    hd__tri_feature_t feature;
    int exact;                /* 1 when exact arithmetic decided (counted by tests) */
} hd__tri_near_t;

int hd__tri_nearest(const double p[3], const double a[3], const double b[3],
                    const double c[3], hd__tri_near_t *out);

/* Rigorous bounds lo2 <= d^2 <= hi2 on the exact squared distance from p to
 * the closed triangle abc, from plain doubles (bounds.c has the proof): no
 * sign is decided, so they hold for every triangle, degenerate ones too.
 * A search discards a triangle whose lo2 exceeds another's hi2 without
 * calling hd__tri_nearest.  Their gap is about u times the triangle's size
 * over the distance, more on slivers (docs/surfaces.md has figures), and
 * they are informative when the triangle's edges are longer than about
 * 2^-170 (with coordinates below 2^100; larger ones are scaled by a power
 * of two).  A degenerate triangle gets lo2 = 0 unless p is
 * certainly in a corner's region.  A NaN or a coordinate beyond 2^511, or
 * large coordinates whose scaling would not be exact: lo2 = 0,
 * hi2 = infinity.  Thread safety: none needed. */
void hd__tri_bounds(const double p[3], const double a[3], const double b[3], const double c[3],
                    double *lo2, double *hi2);

/* A triangle prepared once for hd__tri_bounds_prep: its corners, rounded
 * edges, n = AB x AC, the two edge normals n x AB and AC x n, the error
 * weights of their dot products with a point's AP, |n|^2 and its bound,
 * and outward-rounded reciprocals.  hd__tri_bounds_prep(p, &t, ..) gives
 * the same bits as hd__tri_bounds(p, a, b, c, ..) at about a third of the
 * cost.  Read-only after hd__tri_prep: share it between threads. */
typedef struct hd__tri_prep {
    double a[3], b[3], c[3], ab[3], ac[3], bc[3];
    double n[3], wn[3], mb[3], wb[3], mc[3], wc[3];
    double M, eM, rMu, rMl, rl[3], rd[3];
    int flat;                 /* |n|^2 not certainly positive: no plane */
    int direct;               /* corners below 2^100: no scaling needed */
} hd__tri_prep_t;

void hd__tri_prep(const double a[3], const double b[3], const double c[3], hd__tri_prep_t *t);
void hd__tri_bounds_prep(const double p[3], const hd__tri_prep_t *t, double *lo2, double *hi2);
/* For a search that discards the triangle when lo2 exceeds its threshold
 * skip: when hd__tri_bounds_prep's lo2 is at most skip, the same lo2 and
 * hi2; else a lower bound lo2 > skip, at most hd__tri_bounds_prep's, from
 * the first of its terms that exceeds skip (the plane's, then the
 * edges', then the corners'), and hi2 possibly +infinity: the terms and
 * the upper bound's work past that are saved. */
void hd__tri_bounds_below(const double p[3], const hd__tri_prep_t *t, double skip, double *lo2, double *hi2);

/* The same answer from exact arithmetic alone (tests compare the two). */
int hd__tri_nearest_exact(const double p[3], const double a[3], const double b[3],
                          const double c[3], hd__tri_near_t *out);

/* ---- the surface: a tree of triangles and the queries on it (bvh.c) ----- */

/* One triangle as the tree stores it: its corners and its index in the
 * caller's mesh. */
typedef struct hd__tri {
    double v[3][3];
    size_t index;
} hd__tri_t;

/* A node: its box (exact minima and maxima of its corners); a leaf holds
 * tris[first, first + count), an inner node (count == 0) has its first
 * child at the next node and its second at `second`. */
typedef struct hd__bvh_node {
    hd__box_t box;
    uint32_t first_or_second, count;
} hd__bvh_node_t;

/* A node's frame (hd__bvh_frames): three nearly orthonormal axes a[j],
 * the first along the node's area-weighted normal, and for each an
 * interval [lo[j], hi[j]] holding a[j] . x exactly for every point x of
 * the node's triangles.  Made by the first search that needs it: state 0
 * not yet, 1 being made, 2 made (the fields then read-only), 3 none (the
 * box alone bounds the node; ok 0). */
typedef struct hd__bvh_frame {
    double a[3][3], lo[3], hi[3];
    int ok;
    atomic_int state;
} hd__bvh_frame_t;

typedef struct hd__bvh {
    hd__tri_t *tris;        /* in leaf order */
    hd__box_t *boxes;       /* each triangle's box, in the same order */
    /* triangle k prepared: prep_pool[slot[k] - 1] once slot[k] is neither
     * 0 (not prepared) nor HD__BVH_BUSY (being prepared); the pool fills
     * from its start in the order of first use, *used records so far.
     * Read it through hd__bvh_prep only: position k is not an index of
     * the pool. */
    atomic_uint_least32_t *slot;
    hd__tri_prep_t *prep_pool;
    atomic_size_t *used;
    hd__bvh_node_t *nodes;
    size_t n_tris, n_nodes;
    hd__bvh_frame_t *frames; /* one per node, or NULL (hd__bvh_frames) */
    double frame_h;          /* at least every |lo[j]| and |hi[j]| a frame can have */
    double frame_reach2;     /* the mean squared box diagonal of the largest framed nodes */
} hd__bvh_t;

#define HD__BVH_BUSY UINT32_MAX
/* Triangle k (a position in t->tris) prepared for hd__tri_bounds_prep:
 * prepared by the first search that asks, then shared.  Any thread may
 * ask at any time; the record has hd__tri_prep's bits whoever made it.
 * The pointer stays valid while the tree lives, except that a thread that
 * asked while another was preparing k gets its own copy, valid until its
 * next call. */
const hd__tri_prep_t *hd__bvh_prep_first(const hd__bvh_t *t, size_t k);
HD__INLINE const hd__tri_prep_t *hd__bvh_prep(const hd__bvh_t *t, size_t k) {
    uint_least32_t s = atomic_load_explicit(&t->slot[k], memory_order_acquire);
    if (s != 0 && s != HD__BVH_BUSY) return &t->prep_pool[s - 1];
    return hd__bvh_prep_first(t, k);
}

/* The tree over n triangles given as corner triples (tris[k].index = k's
 * index in the mesh), built on `threads` threads (bvh_build.c), or on the
 * caller's alone; the same tree at any thread count.  The array is taken
 * over (freed: the tree holds its triangles in leaf order).  HD_OK or
 * HD_ENOMEM / HD_EOVERFLOW (more than 2^31 triangles), and then the array
 * is still the caller's. */
int hd__bvh_build_threads(hd__bvh_t *t, hd__tri_t *tris, size_t n, int threads);
int hd__bvh_build(hd__bvh_t *t, hd__tri_t *tris, size_t n);
void hd__bvh_free(hd__bvh_t *t);

/* Frames for the nodes of at most 64 triangles of a built tree: an
 * oriented lower bound on a node's distance that hd__bvh_nearest uses in
 * place of the box's for a point whose seed triangle is farther than two
 * diagonals of those nodes (tight on the nearly flat patches a far point
 * sees at an angle; near the surface the box's is as good and cheaper).
 * Each frame is made when a search first needs it (so a near cloud pays
 * for none); searches in several threads may share the tree.  Optional:
 * HD_ENOMEM leaves t->frames NULL and the searches exact without them. */
int hd__bvh_frames(hd__bvh_t *t);

/* The counters of the queries (summed per thread, then over threads). */
typedef struct hd__bvh_stats {
    uint64_t nodes, bounded, kernel, exact, listed, ties;
} hd__bvh_stats_t;

/* The triangle nearest to p: *best (its distance correctly rounded, its
 * closest point and weights) and *index (the smallest index among the
 * triangles at that rounded distance), bit-identical to a loop over every
 * triangle with hd__tri_nearest.  `seed` (a position in t->tris, or
 * SIZE_MAX) is tried first: any triangle is correct, a near one makes the
 * search short; seed_kernel 1 evaluates it with the kernel before
 * anything else (worth it when the previous answer was at a corner: the
 * triangles around a corner then tie without the kernel), 0 bounds it
 * first like any other.  Returns the position of the nearest triangle in
 * t->tris (the next query's seed). */
size_t hd__bvh_nearest(const hd__bvh_t *t, const double p[3], size_t seed, int seed_kernel,
                       hd__tri_near_t *best, size_t *index, hd__bvh_stats_t *st);

/* Work shared by the points of a box B.  hd__bvh_collect writes to out
 * the positions of the triangles whose box is not proven farther than
 * sqrt(r2) from B, in leaf order, and returns their number, or SIZE_MAX
 * when there are more than cap.  For r2 at least next(d*(q))^2 for every
 * point q of B (d*(q) its rounded distance to the mesh), every triangle
 * left out is farther than next(d*(q)) from each q: so
 * hd__bvh_nearest_in, which searches only the list (seed first), gives
 * hd__bvh_nearest's answer for each q in B. */
size_t hd__bvh_collect(const hd__bvh_t *t, const hd__box_t *B, double r2, uint32_t *out, size_t cap);
size_t hd__bvh_nearest_in(const hd__bvh_t *t, const double p[3], const uint32_t *list, size_t n, size_t seed,
                          int seed_kernel, hd__tri_near_t *best, size_t *index, hd__bvh_stats_t *st);

/* Lower bounds on distances, proven not to exceed the true distance with
 * every rounding error counted (bvh.c has the proofs); 0 when no bound
 * is certain.  Exposed for the tests. */
double hd__box_lower(const hd__box_t *b, const double p[3]);
/* The frame bound of node k, holding t->tris[first, first + n), of a tree
 * with frames (hd__bvh_frames; the frame is made if it was not): a lower
 * bound on the squared distance from p to the node's triangles, 0 when
 * the node has no frame or no bound is certain. */
double hd__bvh_frame_lower2(const hd__bvh_t *t, size_t k, size_t first, size_t n, const double p[3]);
/* The support bound: min over the corners v of t[0 .. n) of
 * w . (p - v) / |w|, shrunk; any w (it may be rescaled in place). */
double hd__support_lower(const hd__tri_t *t, size_t n, const double p[3], double *w);

/* 1 when the corners are collinear or coincident (the triangle is a
 * segment or a point), decided exactly. */
int hd__tri_degenerate(const double a[3], const double b[3], const double c[3]);

/* ---- surface to surface: the enclosure's branch and bound (m2m.c) ------- */

/* One directed search h(X, Y): X's triangles in index order, Y's tree. */
typedef struct hd__m2m_job {
    const hd__tri_t *from;
    size_t n_from;
    const hd__bvh_t *to;
    const unsigned char *drop; /* 1 for a face of X to skip (shared), or NULL */
    const uint32_t *vertex;    /* corner 3 f + j's vertex index in X, < n_vertices
                                  (equal indices: equal corners), or NULL */
    size_t n_vertices;
    double tol;                /* absolute, > 0 */
    double done_below;         /* a face is finished once its bound is <= this
                                  (the predicate's d; -infinity otherwise) */
    double stop_above;         /* stop once a lower bound exceeds this (the
                                  predicate's d; +infinity otherwise) */
    int per_face;              /* refine every face against its own lower
                                  bound only (per-face maxima) */
    uint64_t max_splits;       /* per face; 0: no limit */
    int threads;               /* >= 1 */
    double *face_lower, *face_upper; /* n_from each, or NULL */
} hd__m2m_job_t;

typedef struct hd__m2m_result {
    double lower, upper;
    size_t face;               /* the witness's face of X (SIZE_MAX: none) */
    double bary[3], point[3], witness_distance, witness_error;
    size_t face_b;             /* its nearest triangle's index in Y */
    double point_b[3];
    uint64_t dropped, splits, kernel_calls;
    int capped;                /* some face stopped at max_splits or the
                                  deepest level */
} hd__m2m_result_t;

/* Run the search (m2m.c has the proof that lower <= RN(h) and h <= upper).
 * The result does not depend on job->threads.  HD_OK or HD_ENOMEM. */
int hd__m2m_run(const hd__m2m_job_t *job, hd__m2m_result_t *out);

/* A bound for a sub-triangle T whose corners are nearest to different
 * triangles t1, t2 of Y: given a[k] >= d(corner k, t1) and b[k] >=
 * d(corner k, t2), min(U, a bound >= max over y in T of min(d(y, t1),
 * d(y, t2))), rounded up (m2m.c has the proof).  U when a value is not
 * finite.  Thread safety: none needed. */
double hd__m2m_bent_bound(const double a[3], const double b[3], double U);

/* A bound carried from an anchor point a to a point p: given hi >= d(a, t)
 * for a set t (a triangle of Y, or Y), d(p, t) <= d(a, t) + |p - a| <=
 * the result, the distance and the sum rounded up (m2m.c).  Infinite when
 * hi or a coordinate is not finite.  Thread safety: none needed. */
double hd__m2m_carried_bound(double hi, const double a[3], const double p[3]);

/* The candidate list of a sub-triangle whose computed corners are c, with
 * U >= d(y, Y) for every y of their hull and e the face's slack (m2m.c):
 * writes to out every triangle of T (positions, from the tree in leaf
 * order, or from from[0 .. n_from) in its order when from is not NULL)
 * whose box is not proven farther than up(U + 2e) from the corners' box
 * widened by 2e, and returns their number, or SIZE_MAX when there are
 * more than cap.  Every point within 2e of the hull (a corner of a
 * descendant sub-triangle) then has a nearest triangle of T in the list,
 * if from (when given) had one (m2m.c has the proof).  Thread safety:
 * reads T only. */
size_t hd__m2m_candidates(const hd__bvh_t *T, const double c[3][3], double U, double e, const uint32_t *from,
                          size_t n_from, uint32_t *out, size_t cap);

/* drop_x[k] = 1 for each triangle of x whose three corners are, as a multiset,
 * bit-identical to those of a triangle of y, *count_x of them; and the
 * same for y against x in drop_y (unless NULL), *count_y.  HD_OK or
 * HD_ENOMEM. */
int hd__m2m_shared(const hd__tri_t *x, size_t nx, const hd__tri_t *y, size_t ny, unsigned char *drop_x,
                   unsigned char *drop_y, size_t *count_x, size_t *count_y);
/* ---- the sign: the winding number of a closed mesh (winding.c) --------- */

/* One triangle to sign against: its corners and the caller's indices of
 * them (the messages name vertices by these; the k-th record is triangle
 * k). */
typedef struct hd__wtri {
    double v[3][3];
    uint64_t vi[3];
} hd__wtri_t;

/* A closed mesh prepared for winding numbers (read-only once built: share
 * it between threads). */
typedef struct hd__solid hd__solid_t;

/* Check that the n triangles form a closed, consistently oriented surface
 * (winding.c states the rule: corners with equal coordinates are one
 * vertex, every edge used as often each way) and prepare them.  HD_EINVAL
 * naming an offending edge (its vertices, by the smallest caller index at
 * those coordinates, and a triangle using it) when they do not;
 * HD_ENOMEM, HD_EOVERFLOW.  Corners must be finite. */
int hd__solid_build(hd__solid_t **out, const hd__wtri_t *t, size_t n, hd_error_t *err);
void hd__solid_free(hd__solid_t *s);

/* The winding number of the surface around p, exact, for p off the
 * surface.  *on_surface = 1 (and the count is meaningless) when the search
 * met a triangle holding p; a point on the surface may also go unnoticed,
 * so callers decide "on the surface" by the distance. */
long hd__solid_winding(const hd__solid_t *s, const double p[3], int *on_surface);

#endif
