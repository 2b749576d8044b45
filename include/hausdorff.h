/*
 * hausdorff.h -- exact Hausdorff distance between 3D point sets.
 *
 * This is the public header of libhausdorff (the optional MPI library adds
 * hausdorff_mpi.h).  Everything a C user needs is declared and documented
 * here; nothing else needs to be read.
 *
 * A first program:
 *
 *     #include <hausdorff.h>
 *     #include <stdio.h>
 *
 *     int main(void) {
 *         double a[] = { 0,0,0,  1,0,0,  0,1,0 };
 *         double b[] = { 0,0,0.5,  1,0.25,0 };
 *         hd_points_t A = hd_points_f64(a, 3), B = hd_points_f64(b, 2);
 *         hd_options_t opt;
 *         hd_options_init(&opt);            // algorithm "auto", every core
 *         hd_symmetric_t r;
 *         hd_error_t err;
 *         if (hd_hausdorff(&A, &B, &opt, &r, &err) != HD_OK) {
 *             fprintf(stderr, "hausdorff: %s\n", err.message);
 *             return 1;
 *         }
 *         printf("H = %.17g, realised by A[%zu] and B[%zu]\n",
 *                r.distance, r.ab.i, r.ab.j);
 *         return 0;
 *     }
 *
 * Build with `cc prog.c $(pkg-config --cflags --libs hausdorff)`, or in CMake
 * with `find_package(hausdorff)` and `target_link_libraries(app hausdorff::hausdorff)`.
 *
 * Conventions, as in SQLite and libuv:
 *  - Every call that can fail returns an int: HD_OK (0) or a negative HD_E*
 *    code.  hd_strerror() names a code.  Results come back through
 *    out-pointers.  When a call fails and the caller passed an hd_error_t,
 *    it holds the code and a sentence with context ("FILE:LINE: reason").
 *    There is no global error state; the library never aborts or exits.
 *  - The caller owns what it passes in.  What the library allocates is freed
 *    with the matching hd_*_free(), which accepts NULL.
 *  - Exact means bit-identical to brute force in doubles: every algorithm
 *    evaluates squared distances as dx*dx + dy*dy + dz*dz, left to right,
 *    without fused multiply-add, compares squared values, and takes one sqrt
 *    at the end.  Float inputs are widened to double exactly.
 *  - Ties break by the smallest index: the witness (i, j) of a directed
 *    distance is the smallest i in A whose nearest-neighbour distance is the
 *    maximum, and the smallest j in B at that distance from A[i].  So the
 *    witness is the same at any thread count and for every algorithm.
 *  - Thread safety: functions are reentrant; a built index is immutable and
 *    may be queried from many threads at once.  Seeds are explicit.
 *  - Inputs are borrowed and must not change during a call: points are
 *    checked (finite, within 1e153) once, when the call starts, and a
 *    coordinate that another thread rewrites afterwards (to NaN, say) makes
 *    the result meaningless.
 */
#ifndef HAUSDORFF_H
#define HAUSDORFF_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define HD_VERSION_MAJOR 0
#define HD_VERSION_MINOR 1
#define HD_VERSION_PATCH 0
#define HD_VERSION_STRING "0.1.0"

/* HD_EXTERN marks the public functions, as libuv's UV_EXTERN does.  The
 * library's own build defines HD_BUILDING (CMakeLists.txt): the functions
 * are exported, everything else stays hidden (-fvisibility=hidden).  A
 * program that links the DLL on Windows defines HD_SHARED, which imports
 * them; any other use (static library, or a shared one on ELF or Mach-O)
 * needs neither. */
#if defined(_WIN32) || defined(__CYGWIN__)
#if defined(HD_BUILDING)
#define HD_EXTERN __declspec(dllexport)
#elif defined(HD_SHARED)
#define HD_EXTERN __declspec(dllimport)
#else
#define HD_EXTERN
#endif
#elif defined(HD_BUILDING) && defined(__GNUC__)
#define HD_EXTERN __attribute__((visibility("default")))
#else
#define HD_EXTERN
#endif

/* ------------------------------------------------------------------------
 * Result codes.  One table; hd_strerror() gives the short text of each.
 * ---------------------------------------------------------------------- */
#define HD_ERRNO_MAP(XX)                                                    \
    XX(OK, 0, "success")                                                    \
    XX(EINVAL, -1, "invalid argument")                                      \
    XX(ENOMEM, -2, "out of memory")                                         \
    XX(EEMPTY, -3, "empty point set")                                       \
    XX(ENONFINITE, -4, "coordinate is NaN or infinite")                     \
    XX(ERANGE, -5, "coordinate magnitude too large (limit 1e153)")          \
    XX(EIO, -6, "input/output error")                                       \
    XX(EFORMAT, -7, "malformed input")                                      \
    XX(EUNSUPPORTED, -8, "unsupported format or feature")                   \
    XX(ETHREAD, -9, "could not start a thread")                             \
    XX(EOVERFLOW, -10, "size overflow")                                     \
    XX(EALGORITHM, -11, "unknown algorithm")

enum {
#define HD__ERRNO_ENUM(name, value, text) HD_##name = value,
    HD_ERRNO_MAP(HD__ERRNO_ENUM)
#undef HD__ERRNO_ENUM
    /* The table's explicit end: the most negative code (codes run from 0
     * down to it without gaps).  An enumerator after the table would be
     * HD_EALGORITHM + 1, i.e. equal to HD_EOVERFLOW. */
    HD__ERRNO_MIN = HD_EALGORITHM
};

/* Largest coordinate magnitude accepted.  Beyond it squared differences could
 * overflow a double (3 * (2e153)^2 < DBL_MAX); such input is refused with
 * HD_ERANGE, never answered wrongly. */
#define HD_MAX_COORD 1e153

/* Context of a failure, filled by any call that takes one (it may be NULL).
 * `message` is a complete sentence such as "cloud.ply:12: expected 3 numbers,
 * found 2"; a sentence longer than 1023 bytes has its file names shortened
 * in their middle ("/data/very...t2.xyz"), so that what went wrong and why
 * stay whole.  `line` (1-based, text input) and `offset` (bytes, binary
 * input) are -1 when they do not apply. */
typedef struct hd_error {
    int code;
    long long line;
    long long offset;
    char message[1024];
} hd_error_t;

/* The short text of a result code ("empty point set"); never NULL. */
HD_EXTERN const char *hd_strerror(int code);
/* The symbolic name of a result code ("HD_EEMPTY"); never NULL. */
HD_EXTERN const char *hd_err_name(int code);
/* The library's version, "MAJOR.MINOR.PATCH". */
HD_EXTERN const char *hd_version(void);

/* ------------------------------------------------------------------------
 * Point sets: a view over caller memory, never copied by the view itself.
 * ---------------------------------------------------------------------- */
typedef enum hd_dtype { HD_FLOAT64 = 0, HD_FLOAT32 = 1 } hd_dtype_t;

/* `count` points, point k's coordinate c (0=x, 1=y, 2=z) at
 *     (char *)data + k * stride + c * cstride
 * read as a double or a float.  Strides may be negative (numpy views).  The
 * caller keeps the memory alive for the duration of the call it is passed
 * to (and for the life of an index built on it).
 *
 * Zero strides are defaults, not broadcasts: stride 0 means 3 elements
 * (packed xyz) and cstride 0 means one element (x, y, z adjacent), so
 * {data, count, dtype, 0, 0} is a packed array.  A broadcast view (one
 * point repeated, numpy's broadcast_to) cannot be described: stride 0
 * would read count consecutive points.  For a Hausdorff distance pass the
 * point once (count 1): repeating it changes neither the distance nor the
 * witness, whose index is that of its first copy, 0.  Where repetition
 * counts (per-point distances, percentiles, means), repeat it in memory.
 *
 * Alignment: a packed view (stride 0 or 3 elements, cstride 0 or one
 * element) is read through double or float pointers, so `data` must be
 * aligned to the element, 8 bytes for doubles and 4 for floats, as every C
 * array of double or float is.  Every call that takes points refuses a
 * misaligned packed view with HD_EINVAL (copy it first).  A view with any
 * other strides is read byte by byte and may lie at any address. */
typedef struct hd_points {
    const void *data;
    size_t count;
    hd_dtype_t dtype;
    ptrdiff_t stride;
    ptrdiff_t cstride;
} hd_points_t;

/* Views over packed x,y,z triples. */
HD_EXTERN hd_points_t hd_points_f64(const double *xyz, size_t count);
HD_EXTERN hd_points_t hd_points_f32(const float *xyz, size_t count);

/* Point k of a view, widened to double (exact for float).  No checks. */
HD_EXTERN void hd_points_get(const hd_points_t *p, size_t k, double out[3]);

/* ------------------------------------------------------------------------
 * Options.
 * ---------------------------------------------------------------------- */
typedef enum hd_algorithm {
    HD_ALG_AUTO = 0,   /* the default engine: fastest exact algorithm */
    HD_ALG_NAIVE,      /* Algorithm 1 (NAIVEHDD) */
    HD_ALG_EARLYBREAK, /* Algorithm 2 (Taha & Hanbury) */
    HD_ALG_INC,        /* incremental dual-tree (Nutanong, Jacox & Samet) */
    HD_ALG_NOHD,       /* Algorithms 3-5 */
    HD_ALG_OHD,        /* Algorithms 6-7 */
    HD_ALG_FRAMEWORK,  /* Algorithm 8: NOHD / EARLYBREAK / OHD by overlap */
    HD_ALG_KDTREE,     /* one exact nearest-neighbour search per point of A */
    HD__ALG_COUNT
} hd_algorithm_t;

typedef struct hd_options {
    hd_algorithm_t algorithm; /* HD_ALG_AUTO */
    int threads;              /* 0: every core; 1: serial */
    uint64_t seed;            /* randomisation (EARLYBREAK, OHD sample); 0 */
    int depth;                /* NOHD octree depth on A; 6 */
    double lambda;            /* OHD sample fraction of |A|; 0.01 */
    double theta;             /* framework overlap threshold; 0.33 */
    int early_break;          /* NOHD early breaking (0 = nNOHD); 1 */
    int culling;              /* OHD point culling (0 = nOHD); 1 */
    int exclude_common;       /* EARLYBREAK skips A points found in B; 1 */
} hd_options_t;

/* Fill `opt` with the defaults shown above. */
HD_EXTERN void hd_options_init(hd_options_t *opt);

/* Algorithm names: "auto", "naive", "earlybreak", "inc", "nohd", "ohd",
 * "framework", "kdtree".  hd_algorithm_from_name returns HD_EALGORITHM for
 * an unknown name.  hd_algorithm_name never returns NULL. */
HD_EXTERN int hd_algorithm_from_name(const char *name, hd_algorithm_t *out);
HD_EXTERN const char *hd_algorithm_name(hd_algorithm_t alg);

/* ------------------------------------------------------------------------
 * Results.
 * ---------------------------------------------------------------------- */
/* Counters that let a benchmark explain itself.  Each is a sum over threads. */
typedef struct hd_stats {
    uint64_t distance_evals; /* point-to-point squared distances evaluated */
    uint64_t nodes_visited;  /* tree nodes or buckets visited */
    uint64_t points_culled;  /* points of A discarded without an NN search */
    uint64_t peak_bytes;     /* the most bytes the default engine's
                                structures held at once during the call
                                (its high-water mark, measured; for
                                hd_hausdorff the call's, in both
                                directions' stats); 0 for the other
                                algorithms and the index, which do not
                                measure it */
} hd_stats_t;

/* A directed distance h(A,B) = max over a in A of min over b in B |a - b|. */
typedef struct hd_result {
    double distance;          /* sqrt(distance2) */
    double distance2;         /* the squared distance, as evaluated */
    size_t i;                 /* witness: index in A (smallest on ties) */
    size_t j;                 /* witness: index in B (smallest on ties) */
    hd_algorithm_t algorithm; /* the algorithm that actually ran */
    hd_stats_t stats;
    double seconds;           /* wall-clock time of the computation */
} hd_result_t;

/* The symmetric distance H(A,B) = max(h(A,B), h(B,A)). */
typedef struct hd_symmetric {
    double distance;
    hd_result_t ab;   /* h(A,B): ab.i indexes A, ab.j indexes B */
    hd_result_t ba;   /* h(B,A): ba.i indexes B, ba.j indexes A */
    double alpha;     /* overlap degree of the bounding boxes, see below */
    int disjoint;     /* 1 when the bounding boxes do not intersect */
    double seconds;
} hd_symmetric_t;

/* ------------------------------------------------------------------------
 * Distances.
 * ---------------------------------------------------------------------- */

/* h(A,B), the directed Hausdorff distance from A to B.
 *
 * A, B: views over caller memory, read only during the call.  Both must be
 *   non-empty (HD_EEMPTY), finite (HD_ENONFINITE) and within HD_MAX_COORD
 *   (HD_ERANGE).
 * opt: NULL for the defaults.  Every field is checked (HD_EALGORITHM for
 *   an unknown algorithm, HD_EINVAL for threads < 0, depth outside 1..21,
 *   lambda outside (0, 1], theta outside [0, 1]); `algorithm` and `threads`
 *   are used, and each other field only by the algorithms its comment in
 *   hd_options_t names (none by HD_ALG_AUTO).
 * out: receives the distance and the witness.
 * err: NULL, or receives the context of a failure.
 * Errors: HD_EINVAL (NULL argument, bad option), HD_EEMPTY, HD_ENONFINITE,
 *   HD_ERANGE, HD_ENOMEM, HD_ETHREAD.
 * Thread safety: reentrant; it may start opt->threads threads of its own. */
HD_EXTERN int hd_directed(const hd_points_t *A, const hd_points_t *B,
                          const hd_options_t *opt, hd_result_t *out,
                          hd_error_t *err);

/* H(A,B) with both directions and their witnesses.  With the framework
 * algorithm each direction is chosen by the overlap; out->ab.algorithm and
 * out->ba.algorithm say what ran.  Same arguments (the same option
 * fields) and errors as hd_directed. */
HD_EXTERN int hd_hausdorff(const hd_points_t *A, const hd_points_t *B,
                           const hd_options_t *opt, hd_symmetric_t *out,
                           hd_error_t *err);

/* The overlap degree alpha of the bounding boxes of A and B, as the
 * framework (Algorithm 8) uses it.  The paper leaves alpha undefined; here,
 * per axis k, r_k = |I_k| / min(|A_k|, |B_k|) where I_k is the intersection
 * of the two extents (r_k = 1 when that minimum is 0 and the extents meet),
 * and alpha = r_x * r_y * r_z.  So alpha is 0 when the boxes just touch and
 * 1 when they coincide (or one box's extent lies within the other's on every
 * axis).  *disjoint is 1 when the boxes do not intersect (alpha is then 0).
 * No options.  Errors: as hd_directed. */
HD_EXTERN int hd_overlap(const hd_points_t *A, const hd_points_t *B,
                         double *alpha, int *disjoint, hd_error_t *err);

/* ------------------------------------------------------------------------
 * A reusable index of B: build once, query many times.
 * ---------------------------------------------------------------------- */
typedef struct hd_index hd_index_t;

/* A rigid (or any affine) transform applied to query points on the fly:
 *     x' = ((r[0]*x + r[1]*y) + r[2]*z) + t[0]
 *     y' = ((r[3]*x + r[4]*y) + r[5]*z) + t[1]
 *     z' = ((r[6]*x + r[7]*y) + r[8]*z) + t[2]
 * evaluated in double in exactly this order, without fused multiply-add, so a
 * brute force that applies the same formula agrees to the bit. */
typedef struct hd_transform {
    double r[9];
    double t[3];
} hd_transform_t;

/* The identity transform. */
HD_EXTERN void hd_transform_identity(hd_transform_t *T);

/* Build an index of B.
 *
 * The index BORROWS B: it may keep a pointer to B's memory, which the caller
 * must keep alive and unchanged until hd_index_free().  What the index
 * allocates itself (reordered coordinates, bucket boxes) is at most a few
 * tens of bytes per point and is freed by hd_index_free().
 * opt: NULL for defaults; only opt->threads is read (for the build; < 0 is
 *   HD_EINVAL): `algorithm` and the other fields are ignored.
 * Errors: HD_EINVAL, HD_EEMPTY, HD_ENONFINITE, HD_ERANGE, HD_ENOMEM,
 *   HD_EOVERFLOW, HD_ETHREAD.
 * Thread safety: the built index is immutable; any number of threads may
 * query it at once. */
HD_EXTERN int hd_index_build(const hd_points_t *B, const hd_options_t *opt,
                             hd_index_t **out, hd_error_t *err);

/* Free an index.  NULL is accepted. */
HD_EXTERN void hd_index_free(hd_index_t *idx);

/* Number of points of the indexed set. */
HD_EXTERN size_t hd_index_count(const hd_index_t *idx);

/* Bytes the index allocated itself (not counting the borrowed points). */
HD_EXTERN size_t hd_index_memory(const hd_index_t *idx);

/* h(T(A), B) against an index of B; T NULL means the identity.  The witness
 * indexes A and B in their original order.  A is read during the call only.
 * opt: NULL for defaults; only opt->threads is read: the index always runs
 * the default engine's search (out->algorithm is HD_ALG_AUTO), so
 * `algorithm` and the other fields are ignored.
 * Errors: as hd_directed; a point that T makes NaN or infinite is
 * HD_ENONFINITE, one it carries beyond HD_MAX_COORD is HD_ERANGE. */
HD_EXTERN int hd_index_directed(const hd_index_t *idx, const hd_points_t *A,
                                const hd_transform_t *T,
                                const hd_options_t *opt, hd_result_t *out,
                                hd_error_t *err);

/* Per-point nearest neighbours: for each point k of Q (after T, if not
 * NULL), dist[k] = min over B |T(q_k) - b| and nearest[k] = the smallest
 * index in B at that distance.  Either output may be NULL; each has
 * Q->count elements.  Exact, at any thread count.  The answers come from
 * the per-point structures hd_distances uses, built for B and T(Q) during
 * the call (about 36 bytes per point of each, freed before returning):
 * the index's own tree is made for the Hausdorff distance's early
 * breaking, and one complete search of it per point costs more.  opt: as hd_index_directed (only
 * opt->threads is read; `algorithm` is ignored).  Errors: as
 * hd_index_directed. */
HD_EXTERN int hd_index_nearest(const hd_index_t *idx, const hd_points_t *Q,
                               const hd_transform_t *T,
                               const hd_options_t *opt, double *dist,
                               size_t *nearest, hd_error_t *err);

/* ------------------------------------------------------------------------
 * Analysis: where the deviation is.  Per-point nearest-neighbour distances
 * and what is derived from them (percentile Hausdorff such as HD95, mean
 * distances, Chamfer distances, histograms).  docs/analysis.md has the
 * definitions, with the tools each one agrees with.
 * ---------------------------------------------------------------------- */

/* Per-point nearest neighbours in both directions: for each point k of A,
 * dist_ab[k] = min over B |a_k - b| and nearest_ab[k] = the smallest index
 * in B at that distance; dist_ba and nearest_ba likewise for the points of
 * B against A.  Each output may be NULL (a direction with both outputs NULL
 * is skipped); dist_ab/nearest_ab hold A->count elements, dist_ba/nearest_ba
 * B->count.  Exact: bit-identical to a brute force, at any thread count.
 * Each set is sorted once along a Morton curve into an octree of small
 * buckets; each structure is searched by the other set's points, a group
 * of neighbouring queries at a time.  It holds a copy of the coordinates
 * (about 36 bytes per point per set while searching, up to about 39
 * while building), freed before returning.  opt: NULL for defaults; only
 * opt->threads is read (the method above is the only one: `algorithm` and
 * the other fields are ignored).  Thread safe for distinct outputs.
 * Errors: as hd_directed. */
HD_EXTERN int hd_distances(const hd_points_t *A, const hd_points_t *B,
                           const hd_options_t *opt, double *dist_ab,
                           size_t *nearest_ab, double *dist_ba,
                           size_t *nearest_ba, hd_error_t *err);

/* Percentiles of n values with numpy's default method ("linear", Hyndman &
 * Fan's definition 7), bit-identical to numpy.percentile(values, p): for
 * the sorted values v, pos = (n - 1) * (p / 100), lo = floor(pos),
 * t = pos - lo, result = v[lo] + (v[lo+1] - v[lo]) * t (computed as
 * v[lo+1] - (v[lo+1] - v[lo]) * (1 - t) when t >= 0.5, as numpy does); the
 * maximum when pos >= n - 1.  Found by selection on a copy (values are not
 * modified), without sorting.  p in [0, 100]; np requests, np results.
 * Errors: HD_EINVAL (p outside [0, 100], NULL), HD_EEMPTY (n = 0),
 * HD_ENONFINITE (a NaN value), HD_ENOMEM. */
HD_EXTERN int hd_percentiles(const double *values, size_t n, const double *p,
                             size_t np, double *out, hd_error_t *err);
HD_EXTERN int hd_percentile(const double *values, size_t n, double p,
                            double *out, hd_error_t *err);

/* Percentile Hausdorff distances, e.g. HD95 with p = 95.  p = 100 gives
 * the Hausdorff distances themselves. */
typedef struct hd_percentile {
    double p;
    double ab;        /* P-th percentile of the distances of A's points to B */
    double ba;        /* ... of B's points to A (NaN when not computed) */
    double symmetric; /* max(ab, ba): MONAI's compute_hausdorff_distance */
    double pooled;    /* P-th percentile of both directions' distances
                         together: medpy's hd95 */
} hd_percentile_t;

/* From per-point distances (hd_distances): d_ab has n_a values; d_ba may be
 * NULL (then ba, symmetric and pooled are NaN).  Errors: as hd_percentiles. */
HD_EXTERN int hd_percentile_of(const double *d_ab, size_t n_a,
                               const double *d_ba, size_t n_b, double p,
                               hd_percentile_t *out, hd_error_t *err);

/* From the point sets: the same bits as hd_distances then
 * hd_percentile_of, at any thread count, without computing every distance:
 * the exact distances of a sample bracket the percentile's ranks, the
 * points proven outside the brackets are only counted, and the ranks are
 * selected among the exact distances of the others (docs/analysis.md,
 * "Without every distance").  Only opt->threads is read.  It holds the
 * structures hd_distances holds, and the distances inside the brackets.
 * Thread safe.  Errors: as hd_distances, and HD_EINVAL for p outside
 * [0, 100]. */
HD_EXTERN int hd_hausdorff_percentile(const hd_points_t *A,
                                      const hd_points_t *B,
                                      const hd_options_t *opt, double p,
                                      hd_percentile_t *out, hd_error_t *err);

/* Sums, means and Chamfer distances of per-point distances.  Sums are
 * correctly rounded: the exact sum of the doubles rounded once to nearest
 * even (Python's math.fsum), so they do not depend on the order of the
 * values (the same at any thread count, and from hausdorff_mpi.h's
 * hd_mpi_summarize for any split over ranks).  Means and Chamfer figures
 * are computed from the rounded sums as doubles without an exponent limit
 * would compute them: a sum of squares beyond DBL_MAX (possible within the
 * 1e153 coordinate limit) is +inf, but the means and Chamfer distance made
 * from it are finite whenever they are at most DBL_MAX.  "2" means squared distances
 * (d * d of each reported distance).  With d_ba NULL every field that needs
 * B's distances is NaN. */
typedef struct hd_summary {
    size_t n_ab, n_ba;          /* numbers of distances */
    double max_ab, max_ba;      /* h(A,B), h(B,A) */
    double sum_ab, sum_ba;      /* sum of distances */
    double sum2_ab, sum2_ba;    /* sum of squared distances */
    double mean_ab, mean_ba;    /* mean distance of A's points to B, ... */
    double mean2_ab, mean2_ba;  /* mean squared distance */
    double mean_symmetric;      /* max(mean_ab, mean_ba): the average
                                   Hausdorff distance (Taha & Hanbury) */
    double mean_average;        /* (mean_ab + mean_ba) / 2 */
    double mean_pooled;         /* the sum of both sets' distances (rounded
                                   once) / (n_ab + n_ba): MONAI's symmetric
                                   average surface distance */
    double chamfer;             /* mean2_ab + mean2_ba: THE Chamfer distance
                                   here (squared, mean per set, summed; as
                                   PyTorch3D's chamfer_distance) */
    double chamfer_sum2;        /* squared, summed over both sets (the exact
                                   sum rounded once, not sum2_ab + sum2_ba) */
    double chamfer_mean;        /* mean_ab + mean_ba (not squared, mean) */
    double chamfer_sum;         /* not squared, summed over both sets (rounded
                                   once, not sum_ab + sum_ba) */
} hd_summary_t;

/* Errors: HD_EINVAL, HD_EEMPTY (n_a = 0, or d_ba given with n_b = 0),
 * HD_ENONFINITE (a NaN). */
HD_EXTERN int hd_summarize(const double *d_ab, size_t n_a, const double *d_ba,
                           size_t n_b, hd_summary_t *out, hd_error_t *err);

/* What the distance figures are when A or B is empty (no point): by
 * default an error (HD_EEMPTY), else one value for every figure, because
 * tools disagree: MONAI returns inf or NaN, medpy raises, scikit-image's
 * hausdorff_distance returns inf or 0, some pipelines count a miss as 0.
 * The library's computations refuse an empty set whatever the policy; the
 * tools and the Python module apply it with hd_empty_value. */
typedef enum hd_empty_policy {
    HD_EMPTY_ERROR = 0, /* "error": an empty set is an error (the default) */
    HD_EMPTY_INF,       /* "inf": every figure +inf */
    HD_EMPTY_NAN,       /* "nan": every figure NaN */
    HD_EMPTY_ZERO,      /* "zero": every figure 0 */
    HD_EMPTY_MONAI,     /* "monai": inf when one set is empty, NaN when both are */
    HD_EMPTY_SKIMAGE    /* "skimage": inf when one set is empty, 0 when both are */
} hd_empty_policy_t;

/* The value of every distance figure under `policy` for sets of n_a and n_b
 * points, one of them (or both) 0.  NaN for HD_EMPTY_ERROR, which has no
 * value (the caller reports HD_EEMPTY), and for an unknown policy.  Pure,
 * thread-safe. */
HD_EXTERN double hd_empty_value(hd_empty_policy_t policy, size_t n_a,
                                size_t n_b);
/* The policy's name as above ("error", "inf", ..., "skimage"); NULL for a
 * value that is not a policy, so that a caller can list them all by
 * counting up from 0.  Static storage; thread-safe. */
HD_EXTERN const char *hd_empty_policy_name(hd_empty_policy_t policy);
/* The policy of a name (exact, case-sensitive).  Errors: HD_EINVAL (an
 * unknown name or NULL; *out unchanged).  Thread-safe. */
HD_EXTERN int hd_empty_policy_from_name(const char *name,
                                        hd_empty_policy_t *out);

/* numpy.histogram(values, bins, range=(lo, hi)) to the count: bins equal
 * bins on [lo, hi] (widened to [lo - 0.5, hi + 0.5] when lo == hi), bin k
 * is [edge k, edge k+1) except the last, which includes hi; values outside
 * [lo, hi] are not counted.  counts has `bins` elements.
 * Errors: HD_EINVAL (bins = 0, lo > hi, a bound not finite, NULL),
 * HD_ERANGE (hi - lo overflows). */
HD_EXTERN int hd_histogram(const double *values, size_t n, double lo,
                           double hi, size_t bins, uint64_t *counts,
                           hd_error_t *err);
/* Edge k (0..bins) of that histogram, as numpy.linspace(lo, hi, bins + 1)
 * computes it: k * ((hi - lo) / bins) + lo, and edge `bins` is hi. */
HD_EXTERN double hd_histogram_edge(double lo, double hi, size_t bins,
                                   size_t k);

/* The histograms hd_histogram gives of the distances of A's points to B
 * (counts_ab) and of B's points to A (counts_ba), as hd_distances computes
 * them, without computing every distance: a point whose cheap lower and
 * upper bounds on its distance fall in one bin (or both outside [lo, hi])
 * is counted from them; only the others get their exact distance.  The
 * counts equal hd_histogram's on every exact distance, to the count, at
 * any thread count.  counts_ab (required) and counts_ba (NULL: that
 * direction is skipped) have `bins` elements each, owned by the caller,
 * and are overwritten.  opt may be NULL (the defaults); opt->threads is
 * used.  Errors: HD_EINVAL (NULL counts_ab, bins = 0, lo > hi, a bound
 * not finite, negative threads, invalid points), HD_ERANGE (hi - lo
 * overflows), HD_EEMPTY (an empty set), HD_ENOMEM; the counts are then
 * unspecified.  Thread-safe on distinct outputs. */
HD_EXTERN int hd_hausdorff_histogram(const hd_points_t *A,
                                     const hd_points_t *B,
                                     const hd_options_t *opt, size_t bins,
                                     double lo, double hi,
                                     uint64_t *counts_ab, uint64_t *counts_ba,
                                     hd_error_t *err);

/* ------------------------------------------------------------------------
 * Scores at a distance tolerance, and capped means.  From per-point
 * distances (hd_distances, or any caller's): docs/analysis.md, "Scores at
 * a tolerance", has the definitions and the libraries each one agrees with.
 * ---------------------------------------------------------------------- */

/* How a distance d is compared with a tolerance tau. */
typedef enum hd_tolerance_rule {
    HD_AT_MOST = 0, /* d <= tau: MONAI's compute_surface_dice, DeepMind's
                       surface_distance (NSD) */
    HD_BELOW = 1    /* d < tau: the Tanks and Temples evaluation and the
                       Open3D scripts of reconstruction papers (F-score) */
} hd_tolerance_rule_t;

/* The figures at one tolerance.  A's points are the prediction (a
 * reconstruction, a segmentation), B's the reference.  A "weight" is 1 per
 * point, or the caller's weight (a surfel's area); sums of weights are
 * exact, rounded once (as hd_summarize's sums). */
typedef struct hd_tolerance {
    double tau;
    size_t count_ab, count_ba;   /* points of A (of B) within tau of the other set */
    double within_ab, within_ba; /* their weights (= the counts when unweighted) */
    double total_a, total_b;     /* the weights of all of A, of all of B */
    double precision;            /* within_ab / total_a: A's share near B */
    double recall;               /* within_ba / total_b: B's share near A */
    double fscore;               /* 2 precision recall / (precision + recall);
                                    0 when both are 0 */
    double nsd;                  /* (within_ab + within_ba) / (total_a + total_b):
                                    the normalized surface Dice */
} hd_tolerance_t;

/* The figures at each of n_tau tolerances (taus[k] -> out[k]) in one pass
 * over the distances.  d_ab: n_a distances of A's points to B; d_ba: n_b
 * of B's to A.  w_a, w_b: a weight per point (finite, >= 0), or NULL for
 * 1 each.  Each comparison is made on the double given, so equal inputs
 * give equal counts on every machine.  A distance may be +inf (a point
 * with nothing to be near: never within).  A ratio whose denominator is 0
 * is NaN (an empty side's precision or recall; the NSD of two empty
 * sets); the F-score is NaN when precision or recall is.
 * Errors: HD_EINVAL (NULL where n > 0, a tau NaN or negative, a weight
 * negative or not finite, an unknown rule), HD_ENONFINITE (a NaN distance).
 * Thread safe; nothing is allocated. */
HD_EXTERN int hd_tolerance_scores(const double *d_ab, const double *w_a, size_t n_a,
                                  const double *d_ba, const double *w_b, size_t n_b,
                                  const double *taus, size_t n_tau, hd_tolerance_rule_t rule,
                                  hd_tolerance_t *out, hd_error_t *err);

/* DTU's accuracy and completeness: means of the distances below a cap
 * (the DTU MVS evaluation drops the larger ones as outliers).
 * accuracy = mean of the d_ab < cap, completeness = mean of the d_ba < cap,
 * overall = (accuracy + completeness) / 2; kept_* count the values used.
 * A mean of no values is NaN.  cap = +inf keeps every finite distance.
 * Sums are exact, rounded once.  Errors: HD_EINVAL (NULL where n > 0, cap
 * NaN or <= 0), HD_ENONFINITE (a NaN distance).  Thread safe. */
typedef struct hd_capped_mean {
    double cap;
    size_t kept_ab, kept_ba;
    double accuracy, completeness, overall;
} hd_capped_mean_t;
HD_EXTERN int hd_capped_means(const double *d_ab, size_t n_a, const double *d_ba, size_t n_b,
                              double cap, hd_capped_mean_t *out, hd_error_t *err);

/* ------------------------------------------------------------------------
 * Masks: a binary image (a segmentation) as the point set of its surface
 * voxels, the definition medpy and MONAI use for HD, HD95, ASSD and NSD
 * (docs/analysis.md, "Medical masks").  The command line's NIfTI masks and
 * the Python module's numpy masks both come through here.
 * ---------------------------------------------------------------------- */

/* An image of n[0] x n[1] x n[2] voxels, one byte each, nonzero meaning
 * foreground, voxel (i, j, k) at voxels[(k * n[1] + j) * n[0] + i] (i
 * fastest, as NIfTI stores them; a 2-D image has n[2] = 1).  Its centre
 * goes to the world coordinates
 *     x_c = (((m[c][0] i + m[c][1] j) + m[c][2] k) + m[c][3]) * scale
 * in double, in this order (the multiplication skipped when scale is 1),
 * c = 0, 1, 2.  hd_mask_init sets m to the diagonal of the spacing. */
typedef struct hd_mask {
    const uint8_t *voxels;
    size_t n[3];
    double m[3][4];
    double scale;
} hd_mask_t;
HD_EXTERN void hd_mask_init(hd_mask_t *mask, const uint8_t *voxels, size_t n0, size_t n1, size_t n2,
                            const double spacing[3]);

typedef enum hd_mask_points {
    HD_MASK_SURFACE = 0, /* the foreground voxels binary erosion removes */
    HD_MASK_ALL = 1      /* every foreground voxel */
} hd_mask_points_t;

typedef struct hd_mask_options {
    hd_mask_points_t points; /* HD_MASK_SURFACE (default) */
    int connectivity;        /* 1 (default), 2, 3: scipy's
                                generate_binary_structure(rank, connectivity),
                                6, 18 or 26 neighbours in 3-D, 4 or 8 in 2-D */
    int dims;                /* the erosion's axes: 0 (default) those of more
                                than one voxel; 2: i and j (each slice k on its
                                own); 3: all three */
    hd_dtype_t dtype;        /* the cloud's storage (HD_FLOAT64 default) */
} hd_mask_options_t;
HD_EXTERN void hd_mask_options_init(hd_mask_options_t *opt);

struct hd_cloud; /* hd_cloud_t, below (Reading files) */

/* What hd_mask_points saw. */
typedef struct hd_mask_info {
    size_t foreground;   /* foreground voxels */
    size_t points;       /* points made */
    int surface_dims;    /* axes of the erosion (HD_MASK_SURFACE) */
    int connectivity;    /* its connectivity, at most surface_dims */
} hd_mask_info_t;

/* The points of a mask: with HD_MASK_SURFACE the foreground voxels that
 * binary erosion with the neighbourhood removes, the image's outside
 * counting as background (medpy's mask ^ binary_erosion(mask, structure),
 * MONAI's get_mask_edges; a mask with no axis of more than one voxel is its
 * own surface); with HD_MASK_ALL every foreground voxel.  Points are in
 * storage order (i fastest), so an index names a voxel; the cloud may have
 * 0 points (an empty mask: the caller's empty policy decides).  *out is
 * the library's (hd_cloud_free), format "mask"; info may be NULL.
 * Errors: HD_EINVAL (NULL, a dimension 0, bad options), HD_EOVERFLOW (the
 * voxel count overflows), HD_ENONFINITE or HD_ERANGE (a corner of the
 * image maps beyond HD_MAX_COORD, or beyond float range with
 * HD_FLOAT32), HD_ENOMEM.  On failure *out is NULL.  Thread safe. */
HD_EXTERN int hd_mask_points(const hd_mask_t *mask, const hd_mask_options_t *opt, struct hd_cloud **out,
                             hd_mask_info_t *info, hd_error_t *err);

/* The surfels of a mask, DeepMind's surface-distance's surface (and
 * MONAI's with use_subvoxels=True): one per cube of 2 x 2 x 2 voxels
 * (dims 3) or 2 x 2 pixels of each slice k (dims 2; dims 0: 2 when
 * n[2] = 1, else 3) whose corners are not all foreground nor all
 * background, the outside of the image counting as background, in storage
 * order of the cubes (the cube of voxels i..i+1, j..j+1, k..k+1 for i =
 * -1 .. n[0]-1, i fastest).  Each is placed at its cube's centre, voxel
 * index (i + 1/2, j + 1/2, k + 1/2) through the mask's map (k itself with
 * dims 2), and weighted by the area of the marching-cubes surface inside
 * its cube after the map's linear part (the length of the boundary in
 * 2-D): docs/analysis.md, "Surfels".  *points (format "surfels") and
 * *areas (count doubles, from malloc: free) are the caller's.
 * Errors: as hd_mask_points (dims other than 0, 2, 3: HD_EINVAL).  On
 * failure both are NULL.  Thread safe. */
HD_EXTERN int hd_mask_surfels(const hd_mask_t *mask, int dims, struct hd_cloud **points, double **areas,
                              hd_error_t *err);

/* ------------------------------------------------------------------------
 * Label maps: an integer image (a multi-class segmentation) against
 * another, every label's figures in one call (docs/analysis.md, "Label
 * maps", defines each figure and names the library whose convention it
 * follows).  A is the prediction, B the reference.  Per label, the two
 * binary masks "voxel == label" are cut to the box of the label's voxels
 * in either image (one voxel of margin), so the memory held is bounded by
 * the largest label's box, not by the number of labels; the points are
 * placed by the whole image's indices, so the figures are bit for bit
 * those of the two masks given whole (hd_mask_points and hd_distances).
 * Two surfaces are measured per label:
 *   voxel surfaces (MONAI's and medpy's): the surface voxels of
 *     hd_mask_points, each counting 1: HD, HD_P (MONAI's max of directed
 *     percentiles and medpy's pooled one), ASSD, NSD (MONAI's
 *     compute_surface_dice, use_subvoxels=False);
 *   surfels (DeepMind's surface-distance, and MONAI's compute_surface_dice
 *     with use_subvoxels=True): one per 2 x 2 x 2 cube of voxels (2 x 2 in
 *     2-D) that the boundary crosses, at the cube's centre, weighted by the
 *     area of the marching-cubes surface in it (masks/surfels.c derives
 *     it): their NSD, the area-weighted directed mean distances and
 *     DeepMind's robust Hausdorff distance (area-weighted percentile).
 * ---------------------------------------------------------------------- */

/* The voxel type of a label image. */
typedef enum hd_label_type {
    HD_LABEL_U8 = 0,
    HD_LABEL_I8,
    HD_LABEL_U16,
    HD_LABEL_I16,
    HD_LABEL_U32,
    HD_LABEL_I32,
    HD_LABEL_I64,
    HD_LABEL_U64
} hd_label_type_t;

/* A label image: n[0] x n[1] x n[2] values of `type` at `labels`, laid out
 * and placed as hd_mask_t's voxels (i fastest; a 2-D image has n[2] = 1).
 * hd_label_image_init sets m to the diagonal of the spacing (NULL: 1). */
typedef struct hd_label_image {
    const void *labels;
    hd_label_type_t type;
    size_t n[3];
    double m[3][4];
    double scale;
} hd_label_image_t;
HD_EXTERN void hd_label_image_init(hd_label_image_t *img, const void *labels, hd_label_type_t type, size_t n0,
                                   size_t n1, size_t n2, const double spacing[3]);

typedef struct hd_label_options {
    const int64_t *labels;    /* the labels to measure, in this order; NULL:
                                 every label other than 0 present in A or B,
                                 ascending */
    size_t n_labels;
    double percentile;        /* P of HD_P (default 95) */
    double tau;               /* the NSD's tolerance (default 1), in the
                                 spacing's unit */
    hd_tolerance_rule_t rule; /* HD_AT_MOST (default: MONAI's, DeepMind's) */
    int connectivity;         /* of the surface voxels' erosion: 1 (default),
                                 2, 3, as hd_mask_options_t */
    int dims;                 /* 0 (default): the image's axes of more than
                                 one voxel; 2: each slice on its own (the
                                 erosion as hd_mask_options_t's, the surfels'
                                 squares); 3 */
    hd_empty_policy_t empty;  /* a label absent from A or B (or both):
                                 HD_EMPTY_ERROR (default) fails with
                                 HD_EEMPTY naming it; otherwise every
                                 distance figure of that label is
                                 hd_empty_value's, the NSDs and Dice are
                                 computed (0 with one side empty, NaN with
                                 both, as MONAI and DeepMind) */
    int components;           /* 0 (default): none; else the connectivity of
                                 connected components, 6, 18 or 26 in 3-D
                                 (4 or 8 in 2-D, as 6 and 18 act on one
                                 slice), each listed in the table */
    int threads;              /* for hd_distances: 0 = every core */
} hd_label_options_t;
HD_EXTERN void hd_label_options_init(hd_label_options_t *opt);

/* One label's figures.  Distances in the unit of the image's map. */
typedef struct hd_label_row {
    int64_t label;
    int empty;                 /* 0, or 1 (A has no such voxel), 2 (B has
                                  none), 3 (neither): the distance figures
                                  then follow the policy */
    size_t voxels_a, voxels_b; /* foreground voxels */
    size_t overlap;            /* voxels of the label in both */
    double dice;               /* 2 overlap / (voxels_a + voxels_b); NaN
                                  when both are 0 */
    size_t points_a, points_b; /* surface voxels */
    double hausdorff;          /* max(hd_ab, hd_ba) */
    double hd_ab, hd_ba;       /* directed: A's surface voxels to B's, ... */
    double hd_p;               /* max of the directed P-th percentiles
                                  (MONAI's compute_hausdorff_distance) */
    double hd_p_pooled;        /* P-th percentile of both directions
                                  pooled (medpy's hd95) */
    double assd;               /* mean of both directions pooled (MONAI's
                                  symmetric ASSD, medpy's assd) */
    double asd_ab, asd_ba;     /* directed means (medpy's asd) */
    double nsd;                /* NSD by voxel counts (MONAI's
                                  compute_surface_dice) */
    size_t surfels_a, surfels_b;
    double area_a, area_b;     /* the surfels' total areas */
    double nsd_surfel;         /* NSD by surfel areas (DeepMind's
                                  compute_surface_dice_at_tolerance, MONAI's
                                  use_subvoxels=True) */
    double overlap_ab, overlap_ba; /* DeepMind's surface overlap at tau:
                                  the share of A's (B's) surfel area within
                                  tau of the other's surfels */
    double hd_surfel;          /* DeepMind's compute_robust_hausdorff at
                                  P: max over both directions of the
                                  smallest distance d whose surfels at most
                                  d hold P percent of the direction's area */
    double asd_surfel_ab, asd_surfel_ba; /* DeepMind's
                                  compute_average_surface_distance: the
                                  area-weighted mean distance, A's surfels
                                  to B's, B's to A's */
    size_t components_a, components_b; /* with options.components */
} hd_label_row_t;

/* One connected component of one side of one label. */
typedef struct hd_label_component {
    int64_t label;
    int side;          /* 0: a component of A, 1: of B */
    size_t index;      /* 1.. in storage order of their first voxel */
    size_t voxels;     /* its voxels */
    size_t overlap;    /* of them, voxels of the label on the other side */
    size_t points;     /* its surface voxels */
    double hausdorff;  /* the directed HD of its surface voxels to the
                          other side's surface (+inf when that is empty) */
    double hd_p;       /* the P-th percentile of those distances */
    double nearest;    /* the smallest of them */
    int detected;      /* 1 when it overlaps the other side's label or
                          nearest is within tau (by the options' rule) */
} hd_label_component_t;

/* The table: rows in the order of the labels, then every component of a
 * row's A side, then of its B side, row after row. */
typedef struct hd_label_table {
    hd_label_row_t *rows;
    size_t n_rows;
    hd_label_component_t *components;
    size_t n_components;
} hd_label_table_t;

/* Every label's figures, A (prediction) against B (reference), which have
 * the same sizes (their maps may differ: each places its own voxels).
 * One pass over both images finds each label's counts and box; then, a
 * label at a time, its windows are cut, their surface voxels and surfels
 * found once, the per-point distances found in both directions
 * (hd_distances) and every figure derived from them.  Memory beyond the
 * images: the largest label's two windows, points and surfels, and about
 * 100 bytes per distinct value in the images (an image of a million
 * distinct values, an intensity image given by mistake, costs that much
 * and a window per value).  *out is the library's (hd_label_table_free).  Errors: HD_EINVAL (NULL, sizes that
 * differ or are 0, an unknown type, bad options: percentile outside
 * [0, 100], tau NaN or < 0, connectivity, dims, components), HD_EEMPTY
 * (a label absent from a side under HD_EMPTY_ERROR: the message names
 * it), HD_EOVERFLOW, HD_ENONFINITE or HD_ERANGE (as hd_mask_points),
 * HD_ENOMEM.  On failure *out is NULL.  Thread safe (the images are only
 * read); threads as hd_distances. */
HD_EXTERN int hd_label_map(const hd_label_image_t *a, const hd_label_image_t *b, const hd_label_options_t *opt,
                           hd_label_table_t **out, hd_error_t *err);
/* Frees a table; NULL is accepted. */
HD_EXTERN void hd_label_table_free(hd_label_table_t *table);

/* The area-weighted percentile of DeepMind's compute_robust_hausdorff:
 * the smallest of the n distances d such that the weights of the
 * distances at most d add up to at least p / 100 of all the weights (sums
 * exact, rounded once; p = 0 gives the smallest distance of positive
 * weight... p = 100 the largest of positive weight).  Errors: HD_EINVAL
 * (NULL, p outside [0, 100], a weight negative or not finite, all weights
 * 0), HD_EEMPTY (n = 0), HD_ENONFINITE (a NaN distance), HD_ENOMEM.
 * Thread safe. */
HD_EXTERN int hd_weighted_percentile(const double *d, const double *w, size_t n, double p, double *out,
                                     hd_error_t *err);

/* ------------------------------------------------------------------------
 * Reading files.
 * ---------------------------------------------------------------------- */

/* A point cloud read from a file; the library owns it (hd_cloud_free).
 * Both the struct and `data` come from malloc and hd_cloud_free releases
 * them with free, so a caller may realloc `data` (to append points, say),
 * and may build a cloud of its own with malloc for hd_cloud_free to free. */
typedef struct hd_cloud {
    void *data;        /* count packed xyz triples of dtype */
    size_t count;
    hd_dtype_t dtype;
    char format[16];   /* the format that was read, e.g. "ply" */
    size_t n_faces;    /* faces seen (mesh formats), 0 otherwise */
} hd_cloud_t;

typedef enum hd_mesh_mode {
    HD_MESH_VERTICES = 0, /* the vertex set, as the paper does */
    HD_MESH_SAMPLE = 1    /* `sample` points uniformly by area, seeded */
} hd_mesh_mode_t;

typedef struct hd_read_options {
    const char *format;  /* NULL: by extension, confirmed by magic */
    hd_dtype_t dtype;    /* storage of the result: HD_FLOAT64 default */
    hd_mesh_mode_t mesh; /* for formats with faces; the others (LAS,
                            LAZ, XYZ, PCD, NPY) are read as their points */
    size_t sample;       /* points to sample with HD_MESH_SAMPLE */
    uint64_t seed;       /* sampling seed */
    int threads;         /* parsing threads (text and binary): 0 = every core */
    uint64_t stream_limit; /* most bytes read from an input that is not a
                              regular file (stdin, pipe, FIFO, device):
                              0 = HD_STREAM_LIMIT */
    int fifo_wait_ms;      /* how long a named FIFO's first writer is
                              awaited: <= 0 = HD_FIFO_WAIT_MS */
    int decimal_comma;     /* text (xyz/csv) only.  0 (default): a number
                              written with a decimal comma ("1,5;2,5;3,5")
                              is refused with its line, since "1,500" is
                              1.5 in one locale and 1500 in another.
                              1: commas are decimal separators and fields
                              are separated by ';' or blanks, as European
                              spreadsheets write. */
    uint64_t range_first;  /* with range_count > 0: only the points
                              [range_first, range_first + range_count) of
                              what the whole read gives, numbered from 0
                              (HD_ERANGE when the file has fewer).  LAS,
                              LAZ (only the chunks that meet the range are
                              decoded), NPY and the fixed-size records of
                              binary PLY, PCD and STL touch only the range's
                              bytes, so processes can split one file; other
                              formats are read whole, then cut.  A bad point
                              outside the range is not seen. */
    uint64_t range_count;  /* 0 (default): the whole file */
    unsigned laz_points_per_byte; /* LAZ: the most points a chunk may hold
                              per byte of it, which bounds the memory a
                              small file can ask for (the result's
                              coordinates, 24 bytes a point in double):
                              0 = HD_LAZ_POINTS_PER_BYTE; at most
                              HD_LAZ_POINTS_PER_BYTE_MAX (HD_EINVAL
                              above).  A denser chunk is refused before it
                              is decoded (HD_EUNSUPPORTED); the default
                              reads every shape of data in LASzip's chunks
                              of 50,000 points (docs/formats.md). */
} hd_read_options_t;

/* The defaults of stream_limit (2 GiB) and fifo_wait_ms (30 s). */
#define HD_STREAM_LIMIT ((uint64_t)2 << 30)
#define HD_FIFO_WAIT_MS 30000
/* The default of laz_points_per_byte, and its largest value (a LAZ point
 * costs at least a few thousandths of a bit in the format's most skewed
 * models). */
#define HD_LAZ_POINTS_PER_BYTE 256
#define HD_LAZ_POINTS_PER_BYTE_MAX 4096

/* Fill `opt` with the defaults (by extension, double, vertices). */
HD_EXTERN void hd_read_options_init(hd_read_options_t *opt);

/* Read a point cloud from `path` ("-" reads standard input; then `format`
 * must be given or the content is sniffed).  opt NULL: defaults.
 * A regular file is mapped; any other input is read to its end, at most
 * opt->stream_limit bytes (HD_EFORMAT beyond), and a named FIFO's first
 * writer is awaited at most opt->fifo_wait_ms (HD_EIO after).
 * Errors: HD_EIO (cannot open or read), HD_EFORMAT (malformed: the message
 *   names the file and the line or byte offset), HD_EUNSUPPORTED, HD_EEMPTY
 *   (no points), HD_ENONFINITE, HD_ERANGE, HD_ENOMEM, HD_EOVERFLOW, HD_EINVAL
 *   (bad options).  On failure *out is NULL.
 * No reader allocates more than the file can hold, and nothing is printed.
 * The formats, their variants and their messages: docs/formats.md. */
HD_EXTERN int hd_read_file(const char *path, const hd_read_options_t *opt,
                           hd_cloud_t **out, hd_error_t *err);

/* The number of points hd_read_file(path, opt) would give, from the
 * file's header alone: for LAS, LAZ, NPY and binary PLY, PCD and STL (the
 * formats whose range reads touch only the range; see range_first), once
 * the header and the file's size are checked (LAZ: the chunk table, every
 * layered chunk's own count, and the last chunk decoded, where a header
 * count lower than the data shows).  For a program that splits
 * one file between processes.  opt NULL: defaults; its range is ignored.
 * Errors: those of hd_read_file for the header, and HD_EUNSUPPORTED for
 * every other format or variant (text, OBJ, OFF, ascii PLY/PCD/STL, PLY
 * vertices with list properties), standard input and mesh sampling, whose
 * count needs the whole file read.  *count is 0 on failure.  Thread safe. */
HD_EXTERN int hd_read_count(const char *path, const hd_read_options_t *opt,
                            uint64_t *count, hd_error_t *err);

/* Free a cloud.  NULL is accepted. */
HD_EXTERN void hd_cloud_free(hd_cloud_t *cloud);

/* A view over a cloud (valid while the cloud lives). */
HD_EXTERN hd_points_t hd_cloud_points(const hd_cloud_t *cloud);

/* The formats the reader knows, as a NULL-terminated array of names, each
 * with a one-line description in hd_format_description(). */
HD_EXTERN const char *const *hd_formats(void);
HD_EXTERN const char *hd_format_description(const char *name);

/* The name of the format that `path`'s extension selects, in any case
 * ("ply" for "scan.PLY", "xyz" for "points.csv"), as hd_read_file chooses
 * it when no format is given; NULL when the extension names no format the
 * library reads (no extension, ".dat", ".nii").  The path is not opened, so
 * hd_read_file may still refuse the content.  Never fails; thread safe. */
HD_EXTERN const char *hd_format_of_path(const char *path);

/* ------------------------------------------------------------------------
 * Writing a per-point field back into the input's own format.
 *
 * A deviation is most useful in the file people opened: a `distance`
 * property in PLY, an extra-bytes dimension in LAS and LAZ, a column in
 * text, and the changed points alone in the same format.  Every byte of
 * the input that is not a point left out is kept: PLY's other properties
 * and elements (faces too) in the input's encoding, LAS/LAZ's header, VLRs,
 * point records, waveform data and extended VLRs, text lines verbatim.
 * The formats and what each keeps: docs/formats.md, "Writing a field".
 * ---------------------------------------------------------------------- */
typedef enum hd_keep {
    HD_KEEP_ALL = 0,     /* every point, with the field added */
    HD_KEEP_FARTHER = 1, /* only the points whose value v > threshold */
    HD_KEEP_NEARER = 2   /* only the points whose value v <= threshold */
} hd_keep_t;

typedef struct hd_write_options {
    const char *name;  /* the field's name: NULL = "distance"; letters,
                          digits and '_' (at most 31 bytes, LAS's limit).
                          "" writes no field (a subset of the input as it
                          is; with HD_KEEP_ALL a copy) */
    hd_keep_t keep;    /* which points are written */
    double threshold;  /* D of HD_KEEP_FARTHER / HD_KEEP_NEARER; finite
                          (a NaN value is neither > D nor <= D: never kept) */
    const char *format; /* the output's format ("ply", "las", ...): NULL
                          = the one out_path's extension names; either way
                          it must be the input's (for writing under a
                          temporary name) */
    const hd_read_options_t *read; /* how the input is read (NULL: the
                          defaults): `format`, `decimal_comma` and
                          `laz_points_per_byte` are used, so the points
                          are numbered as hd_read_file numbers them with
                          these options; a range or mesh sampling is
                          refused (HD_EINVAL) */
} hd_write_options_t;

/* Fill `opt` with the defaults: "distance", HD_KEEP_ALL, threshold 0. */
HD_EXTERN void hd_write_options_init(hd_write_options_t *opt);

/* Write out_path: the points of in_path in its own format, point k with
 * values[k] added as the field opt->name, keeping the points that
 * opt->keep selects (in file order).  values holds n doubles, n being the
 * number of points hd_read_file gives for in_path with opt->read (for
 * meshes: the vertices); it is borrowed for the call.
 * Formats (the input's, as its signature or the read options' format
 * or its extension say; out_path's extension, or opt->format, must name
 * the same format):
 *  - PLY ascii and binary: `property double NAME` appended to element
 *    vertex, in the input's encoding and byte order; a value is written
 *    as the shortest decimal that reads back to the same double (ascii).
 *    Every other element and property is kept; a subset keeps element
 *    vertex only (the other elements, faces included, refer to vertices
 *    by index and are left out).
 *  - LAS 1.0-1.4: the header, VLRs and records kept, 8 bytes appended to
 *    each record, described by an extra-bytes VLR (record 4, user
 *    "LASF_Spec"; an existing one gets the descriptor appended, after an
 *    "undocumented" one for bytes it did not describe), the record
 *    length, offsets and (subset) counts, counts by return and bounds
 *    updated; waveform data and extended VLRs follow the points as before.
 *  - LAZ, point formats 6-10 (layered): every layer of every chunk copied
 *    as it is and the field's 8 bytes added as BYTE14 layers; a subset is
 *    HD_EUNSUPPORTED.  Point formats 0-3 (pointwise, LASzip items of
 *    version 2): every chunk decoded and compressed again, the field's 8
 *    bytes in the BYTE item; subsets too.  LASzip 1.x streams are
 *    HD_EUNSUPPORTED.  The library's own encoder writes both.
 *  - XYZ, CSV, TXT, PTS, ASC: every line kept, the value appended to each
 *    point line with the file's separator (a CSV header line gets the
 *    name; a PTS count line the subset's count).  OBJ: a subset keeps its
 *    lines but the vertices left out and the faces; no field (HD_KEEP_ALL
 *    with a name is HD_EUNSUPPORTED).  Other formats: HD_EUNSUPPORTED.
 * The file is written to a temporary beside out_path and renamed over it
 * once complete and flushed to disk, so out_path is either the whole
 * result or untouched.  *written (may be NULL) receives the number of
 * points written.
 * Errors: HD_EINVAL (NULL arguments, n not the file's point count, a bad
 *   name, a field of that name already in the input, out_path the input
 *   itself or an existing file that is not a regular file (a device, a
 *   FIFO: the result is renamed into place), a non-finite threshold),
 *   HD_EUNSUPPORTED (an input that is not a regular file: it must be
 *   read twice; a format or variant above), the
 *   errors of hd_read_file for the input, HD_EIO (out_path cannot be
 *   created or written: the message names it and the system's reason,
 *   a full disk or a file size limit included), HD_ENOMEM.
 * Thread safe (nothing is shared between calls). */
HD_EXTERN int hd_write_field(const char *in_path, const char *out_path,
                             const double *values, size_t n,
                             const hd_write_options_t *opt, size_t *written,
                             hd_error_t *err);

/* One field of hd_write_fields: its name (as opt->name of hd_write_field,
 * but not "") and its n values, point k's being values[k]; both borrowed
 * for the call. */
typedef struct hd_field {
    const char *name;
    const double *values;
} hd_field_t;

/* hd_write_field with n_fields fields at once, in one pass over the file:
 * point k gets fields[0].values[k], ..., fields[n_fields - 1].values[k],
 * in that order (PLY properties, LAS extra-bytes descriptors and bytes,
 * LAZ BYTE14 layers or BYTE item bytes, text columns); opt->keep and
 * opt->threshold select on fields[0]'s values; opt->name is not used.
 * hd_write_field is this call with one field (its "" name: none).
 * Errors: those of hd_write_field, and HD_EINVAL for n_fields 0 or more
 *   than 8191 (65535 bytes, LAS's longest record), a NULL fields or
 *   values, an empty or bad name, two fields of one name; a record or an
 *   extra-bytes VLR with no room for them is HD_EUNSUPPORTED.
 * Thread safe (nothing is shared between calls). */
HD_EXTERN int hd_write_fields(const char *in_path, const char *out_path,
                              const hd_field_t *fields, size_t n_fields,
                              size_t n, const hd_write_options_t *opt,
                              size_t *written, hd_error_t *err);

/* ------------------------------------------------------------------------
 * Surfaces: the distance from every point of a cloud to a triangle mesh.
 *
 * The distance from a point to a triangle is the true Euclidean distance
 * to the closed triangle (its convex hull: a degenerate triangle, with
 * collinear or coincident corners, is the segment or the point it
 * collapses to), correctly rounded: the real number rounded to the nearest
 * double, ties to even, decided by exact arithmetic where doubles cannot
 * decide it.  The distance to a mesh is the smallest over its triangles
 * (rounding is monotone, so it is the correctly rounded distance to the
 * union), and the nearest triangle is the smallest index at that distance:
 * the answers equal a loop over every triangle, bit for bit, at any
 * thread count.
 * ---------------------------------------------------------------------- */
typedef enum hd_index_type { HD_INDEX_U32 = 0, HD_INDEX_U64 = 1 } hd_index_type_t;

/* A triangle mesh as a view over caller memory (nothing is copied by the
 * view itself).  `vertices` is a point view as above (any dtype and
 * strides); `triangles` holds 3 * n_triangles packed indices into it, of
 * uint32_t or uint64_t as index_type says (aligned to their type), corner
 * order free.  Both are borrowed for the duration of the call they are
 * passed to.  A vertex no triangle uses is never read. */
typedef struct hd_mesh {
    hd_points_t vertices;
    const void *triangles;
    size_t n_triangles;
    hd_index_type_t index_type;
} hd_mesh_t;

/* A mesh read from a file; the library owns it (hd_mesh_file_free).
 * Polygons are split into fans (v0, v[k], v[k+1]), k = 1 .. n-2, in file
 * order; an STL's corners are merged into one vertex where their three
 * coordinates are bit-equal (n_merged counts the corners so merged). */
typedef struct hd_mesh_file {
    double *vertices;      /* n_vertices packed xyz doubles (float files
                              widened exactly) */
    size_t n_vertices;
    uint64_t *triangles;   /* 3 * n_triangles indices, each < n_vertices */
    size_t n_triangles;
    size_t n_faces;        /* faces (polygons, facets) in the file */
    size_t n_degenerate;   /* triangles with collinear or coincident
                              corners (repeated indices included): measured
                              as their hull, never an error */
    size_t n_merged;       /* STL corners merged into an earlier vertex */
    char format[16];       /* "ply", "obj", "off" or "stl" */
} hd_mesh_file_t;

/* Read the vertices and faces of a PLY, OBJ, OFF or STL file.  opt: NULL
 * for the defaults; `format`, `threads`, `stream_limit`, `fifo_wait_ms`
 * are read, `dtype` and `mesh` are ignored (vertices are doubles), a range
 * is refused (HD_EINVAL).  Errors: those of hd_read_file, and
 * HD_EUNSUPPORTED for a format without faces, HD_EFORMAT for a face that
 * refers to a vertex the file does not have (the message names the file
 * and the face), HD_EEMPTY for a file without vertices or without faces.
 * A non-finite vertex is HD_ENONFINITE at its line or offset, as in
 * hd_read_file.  On failure *out is NULL.  Thread safe. */
HD_EXTERN int hd_read_mesh(const char *path, const hd_read_options_t *opt,
                           hd_mesh_file_t **out, hd_error_t *err);

/* Free a mesh read by hd_read_mesh.  NULL is accepted. */
HD_EXTERN void hd_mesh_file_free(hd_mesh_file_t *mesh);

/* A view over a mesh read from a file (valid while it lives). */
HD_EXTERN hd_mesh_t hd_mesh_file_view(const hd_mesh_file_t *mesh);

/* What hd_mesh_distances found and did.  The counters sum over threads. */
typedef struct hd_surface_result {
    double distance;        /* h(points, surface): the largest distance */
    size_t i;               /* its point (the smallest index on ties) */
    size_t triangle;        /* that point's nearest triangle */
    size_t n_degenerate;    /* degenerate triangles of the mesh */
    uint64_t kernel_calls;  /* point-to-triangle distances computed */
    uint64_t exact_calls;   /* ... of them decided by exact arithmetic */
    uint64_t triangles_bounded; /* triangles given a cheap lower bound */
    uint64_t nodes_visited; /* tree nodes opened */
    double seconds;         /* wall-clock time of the call */
} hd_surface_result_t;

/* For every point k of P, its distance to the surface of M (see above):
 * dist[k], the nearest triangle triangle[k] (the smallest index among the
 * triangles at that rounded distance), the closest point closest[3k ..
 * 3k+2] on that triangle and its barycentric weights bary[3k .. 3k+2] of
 * the triangle's corners in their stored order (closest point and weights
 * are computed in doubles from the exact nearest feature: within a few
 * rounding errors, not correctly rounded).  Each output may be NULL;
 * dist and triangle hold P->count elements, closest and bary 3 * P->count.
 * out (may be NULL) receives h(P, surface) with its witness and the
 * counters.  The triangles are put in a bounding-volume hierarchy for the
 * call (its size a triangle: docs/surfaces.md, "Memory"; freed before
 * returning) and the points are visited along a Morton curve in groups of
 * neighbours, each starting from its predecessor's nearest triangle.
 * opt: NULL for defaults; only opt->threads is read.
 * Errors: HD_EINVAL (NULL P or M, unknown index_type, an index beyond the
 *   vertices: the message names the triangle), HD_EEMPTY (no points, no
 *   triangles, or triangles without vertices), HD_ENONFINITE / HD_ERANGE
 *   (a point, or a corner of a triangle: the message names it), HD_ENOMEM.
 * Thread safety: reentrant; it may start opt->threads threads. */
HD_EXTERN int hd_mesh_distances(const hd_points_t *P, const hd_mesh_t *M,
                                const hd_options_t *opt, double *dist,
                                size_t *triangle, double *closest,
                                double *bary, hd_surface_result_t *out,
                                hd_error_t *err);

/* ------------------------------------------------------------------------
 * Surface to surface: the Hausdorff distance between two triangle meshes
 * as surfaces (every point of A's triangles, not only its vertices), and
 * between a surface and a point set.
 *
 * The distance from a surface is in general not a rational number (its
 * maximiser can lie inside a triangle of A, on the medial axis of B), so
 * it is returned as an enclosure [lower, upper]:
 *  - upper is rigorous under floating point: the true h(A, B) <= upper.
 *    Every bound is rounded outward, and the rounding error of every point
 *    computed on A is added to the bounds of its sub-triangle.
 *  - lower comes from an explicit witness point of A (point_a, on face_a
 *    at weights bary_a): witness_distance is the correctly rounded
 *    distance from point_a (the double point) to B.  point_a is within
 *    witness_error of the exact point of face_a at those weights (0 when
 *    it is a vertex of A); lower = witness_distance when witness_error is
 *    0, else the largest double below witness_distance minus
 *    witness_error, rounded down: a distance some point of A certainly
 *    has.  So the correctly rounded h lies in [lower, upper].
 *  - upper - lower <= tolerance (the absolute tolerance as used), unless
 *    `converged` is 0 (see hd_surface_options_t.max_splits).
 * Branch and bound over A's triangles: each is split into four at its
 * edge midpoints while its upper bound can exceed the best lower bound by
 * more than the tolerance; a sub-triangle's upper bound is the smaller of
 * Tang et al.'s (the least, over the triangles of B nearest to its
 * corners, of the largest corner distance to that triangle: the distance
 * to a triangle is convex) and the point bound (the largest corner
 * distance to B plus the farthest a point of the sub-triangle can be from
 * its nearest corner).  Faces of A whose corners are bit-identical to a
 * face of B's are at distance 0 and dropped first.  Degenerate triangles
 * are their hulls on both sides.  The result does not depend on the
 * thread count: the same enclosure, witness and counters at 1 thread or
 * many (triangles are taken in fixed batches, each refined against the
 * lower bound of the batches before it).
 * ---------------------------------------------------------------------- */

/* One directed distance h(X, Y) as an enclosure.  "a" is the side the
 * distance is measured from (X), "b" the side it is measured to (Y): for
 * the `ba` output of the calls below, face_a indexes B and face_b A. */
typedef struct hd_enclosure {
    double lower, upper;      /* lower <= RN(h) <= upper, h <= upper */
    double tolerance;         /* the absolute tolerance used */
    int converged;            /* 1: upper - lower <= tolerance */
    size_t face_a;            /* the witness's triangle of X (SIZE_MAX
                                 when X is a point set, and when every
                                 face of X is shared with Y: then there
                                 is no witness, point_a is (0, 0, 0) and
                                 the enclosure is [0, 0]) */
    size_t index_a;           /* the witness's point of X when X is a
                                 point set (SIZE_MAX otherwise) */
    double bary_a[3];         /* its weights of face_a's corners, in
                                 their stored order (dyadic; rounded to
                                 double) */
    double point_a[3];        /* the witness point, as computed */
    double witness_distance;  /* RN(distance from point_a to Y) */
    double witness_error;     /* |point_a - the exact point| bound */
    size_t face_b;            /* point_a's nearest triangle of Y (SIZE_MAX
                                 when Y is a point set) */
    size_t index_b;           /* its nearest point of Y when Y is a point
                                 set (SIZE_MAX otherwise) */
    double point_b[3];        /* that nearest point (within a few
                                 rounding errors) */
    uint64_t faces_dropped;   /* faces of X shared with Y */
    uint64_t faces_split;     /* sub-triangles split in four */
    uint64_t kernel_calls;    /* point-to-triangle distances computed */
    double seconds;           /* wall-clock time of this direction */
} hd_enclosure_t;

typedef struct hd_surface_options {
    double tolerance;  /* 1e-9; 0: as tight as doubles allow (then the
                          tolerance used is a few rounding errors of the
                          coordinates: see docs/surfaces.md) */
    int relative;      /* 1: tolerance times the diagonal of the bounding
                          box of A and B together; 0: absolute */
    int threads;       /* 0: every core; 1: serial */
    uint64_t max_splits; /* 2^20: per face of X, at most this many
                          splits, then its bound stands as it is
                          (converged 0); 0: no limit */
} hd_surface_options_t;

/* Fill `opt` with the defaults shown above. */
HD_EXTERN void hd_surface_options_init(hd_surface_options_t *opt);

/* h(surface A, surface B) into *ab and h(surface B, surface A) into *ba,
 * each enclosed as described above; either may be NULL (a directed
 * distance), not both.  The symmetric H lies in [max(lower), max(upper)].
 * opt: NULL for the defaults.  Errors: HD_EINVAL (NULL meshes, both
 * outputs NULL, a negative or non-finite tolerance, threads < 0, a bad
 * mesh as in hd_mesh_distances), HD_EEMPTY (a mesh without triangles),
 * HD_ENONFINITE, HD_ERANGE, HD_ENOMEM.  Thread safety: reentrant; it may
 * start opt->threads threads. */
HD_EXTERN int hd_surface_hausdorff(const hd_mesh_t *A, const hd_mesh_t *B,
                                   const hd_surface_options_t *opt,
                                   hd_enclosure_t *ab, hd_enclosure_t *ba,
                                   hd_error_t *err);

/* A surface and a point set: *ab = h(surface A, points B) (the farthest
 * point of A's surface from the cloud, enclosed; index_b is its nearest
 * point of B) and *ba = h(points B, surface A), which is exact: lower =
 * upper = the correctly rounded distance (index_a is B's farthest point,
 * face_b its nearest triangle of A).  Either output may be NULL, not both.
 * Errors: as hd_surface_hausdorff, for B as in hd_mesh_distances. */
HD_EXTERN int hd_surface_points_hausdorff(const hd_mesh_t *A,
                                          const hd_points_t *B,
                                          const hd_surface_options_t *opt,
                                          hd_enclosure_t *ab,
                                          hd_enclosure_t *ba,
                                          hd_error_t *err);

/* The predicate "H(A, B) <= d?" (h(A, B) <= d when `directed` is 1),
 * with early exit, refining only what decides d: a face whose rigorous
 * upper bound is <= d is discarded unrefined (first from bounds on its
 * corners without the exact kernel), and the search stops at the first
 * witness whose correctly rounded distance exceeds d.  *answer: 1 (proven
 * <= d: every upper bound <= d), 0 (proven > d: a witness's lower bound
 * > d), or -1 when d lies within the tolerance of the distance: then lower
 * <= d < upper and upper - lower <= tolerance (lower and upper the largest
 * of the directions'), so that a tolerance of 0 decides every d but those
 * within about 2^-48 of the coordinates of the distance.  ab, ba: NULL, or
 * the enclosures as far as the search went: a face discarded by its bound
 * gives no lower bound (lower may be 0 with no witness, face_a SIZE_MAX),
 * and upper is infinity when the search stopped before every face had a
 * bound; ba has lower 0 and upper infinity when h(A, B) alone proved the
 * answer 0.  The answer, enclosures and counters do not depend on the
 * thread count.  Errors: as hd_surface_hausdorff, and HD_EINVAL for d
 * negative or NaN. */
HD_EXTERN int hd_surface_within(const hd_mesh_t *A, const hd_mesh_t *B,
                                double d, int directed,
                                const hd_surface_options_t *opt,
                                int *answer, hd_enclosure_t *ab,
                                hd_enclosure_t *ba, hd_error_t *err);

/* Per-face maxima: for every triangle k of A, face_lower[k] <= RN(the
 * largest distance from a point of triangle k to surface B) and that
 * largest distance <= face_upper[k], each to the tolerance (each face is
 * refined on its own, so this costs more than hd_surface_hausdorff).
 * Shared faces get [0, 0].  ab (may be NULL) receives h(A, B) from the
 * same work.  face_lower and face_upper hold A->n_triangles doubles each;
 * either may be NULL, not both.  Errors: as hd_surface_hausdorff. */
HD_EXTERN int hd_surface_face_maxima(const hd_mesh_t *A, const hd_mesh_t *B,
                                     const hd_surface_options_t *opt,
                                     double *face_lower, double *face_upper,
                                     hd_enclosure_t *ab, hd_error_t *err);

/* hd_mesh_distances with the sign of every distance, for a closed,
 * consistently oriented mesh: sign[k] = -1 when point k is inside the
 * surface, +1 when it is outside, 0 when its distance is 0 (on the
 * surface, or nearer than half the least subnormal).  Inside means that the
 * winding number of the surface around the point (the generalised winding
 * number of Jacobson et al. 2013: the solid angle the surface subtends over
 * 4 pi, an integer on a closed mesh) is not 0; it is decided exactly (the
 * signed count of a ray's crossings with exact predicates and simulation of
 * simplicity, docs/surfaces.md), so points on an edge's or a vertex's line
 * of sight get no guessed sign.  Nested shells: a point is inside when the
 * shells around it do not cancel (an inner shell oriented inward makes a
 * cavity, outward an inner solid).
 * Closed: corners with equal coordinates (-0 = +0) are one vertex; a
 * triangle with two corners on one vertex is skipped; every edge is used as
 * often from u to v as from v to u by the other triangles (once each way on
 * a manifold edge; a non-manifold edge shared by 2k triangles k times each
 * way).  The vertex indices and triangles of the mesh are as for
 * hd_mesh_distances; the other outputs too, bit for bit (each may be NULL,
 * sign too: then only the check and the distances run).  sign holds
 * P->count elements.  The check and the winding tree take about 400 bytes
 * a triangle at their peak, beside hd_mesh_distances' tree, freed before
 * returning.
 * Errors: those of hd_mesh_distances, and HD_EINVAL when the mesh is not
 *   closed and consistently oriented: the message names an offending edge
 *   by its two vertex indices (the smallest index at those coordinates) and
 *   a triangle using it; no output is written then.
 * Thread safety: reentrant; it may start opt->threads threads. */
HD_EXTERN int hd_mesh_signed_distances(const hd_points_t *P,
                                       const hd_mesh_t *M,
                                       const hd_options_t *opt, double *dist,
                                       size_t *triangle, double *closest,
                                       double *bary, int8_t *sign,
                                       hd_surface_result_t *out,
                                       hd_error_t *err);

#ifdef __cplusplus
}
#endif
#endif /* HAUSDORFF_H */
