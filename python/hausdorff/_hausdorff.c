/*
 * _hausdorff.c -- the CPython extension over libhausdorff.
 *
 * This file is a thin layer: it turns Python arguments into the library's
 * views and options, calls the library with the GIL released, and turns
 * results and error codes back into Python objects.  It computes no distance
 * itself, so everything the library guarantees (exact to the bit, the
 * canonical witness, the same answer at any thread count) holds unchanged in
 * Python.
 *
 * Arrays are passed without a copy whenever the layout allows it.  A numpy
 * array of float32 or float64 in native byte order and of shape (N, 3) is
 * described to the library by its data pointer and its two byte strides
 * (hd_points_t.stride and .cstride, negative allowed), so C order, Fortran
 * order, slices with steps and reversed views are all read in place.  Only
 * four cases copy: other numeric types (integers, float16, long double) are
 * converted to float64 as numpy would; non-native byte order is swapped;
 * misaligned data (np.frombuffer at an odd offset) is aligned, since the
 * library may read packed doubles through a double pointer; and a zero
 * stride (np.broadcast_to) is materialised, because the library reads a zero
 * stride as "packed".  The array object is held for as long as
 * the library may read it, and the GIL is released only around library
 * calls, which touch no Python object.
 *
 * Points of 1 or 2 coordinates are padded with zeros to 3-D (one copy), which
 * changes no squared distance; points of 4 or more go, as C-ordered doubles,
 * to _ndim.c, which computes the same doubles as a brute force in any
 * number of coordinates (the library computes in 3-D only).
 *
 * An Index keeps its own C-ordered copy of the indexed points: the library's
 * index may borrow the memory it was built on (hausdorff.h allows it), and a
 * Python caller could otherwise change or free that array while the index
 * lives.  The copy is made once and never written again (the array Python
 * sees has a capsule as its owner, so numpy cannot make it writable), so
 * queries from many Python threads at once are safe (the C index is
 * immutable).
 *
 * Library result codes map to Python exceptions by kind: bad input (invalid
 * argument, empty set, NaN or infinite or too large a coordinate, malformed
 * or unsupported file, unknown algorithm) raises ValueError; out of memory
 * and size overflow raise MemoryError; input/output errors raise OSError;
 * anything else (a thread that could not start) raises RuntimeError.  The
 * message is the library's sentence, which names the set and the point.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "hausdorff.h"
#include "_ndim.h"
#include "_masks.h"

/* hd_index_nearest writes size_t indices straight into an intp array. */
_Static_assert(sizeof(size_t) == sizeof(npy_intp), "size_t and npy_intp differ in size");

/* ------------------------------------------------------------------------
 * Errors.
 * ---------------------------------------------------------------------- */

static PyObject *raise_hd(int rc, const hd_error_t *err) {
    PyObject *type;
    switch (rc) {
    case HD_EINVAL:
    case HD_EEMPTY:
    case HD_ENONFINITE:
    case HD_ERANGE:
    case HD_EFORMAT:
    case HD_EUNSUPPORTED:
    case HD_EALGORITHM: type = PyExc_ValueError; break;
    case HD_ENOMEM:
    case HD_EOVERFLOW: type = PyExc_MemoryError; break;
    case HD_EIO: type = PyExc_OSError; break;
    default: type = PyExc_RuntimeError; break;
    }
    const char *msg = err && err->message[0] ? err->message : hd_strerror(rc);
    PyErr_Format(type, "%s (%s)", msg, hd_err_name(rc));
    return NULL;
}

/* ------------------------------------------------------------------------
 * Point sets: numpy arrays described to the library without a copy.
 * ---------------------------------------------------------------------- */

typedef struct {
    PyArrayObject *arr; /* keeps the memory alive; NULL when unused */
    hd_points_t pts;    /* dims <= 3: the (N, 3) view the library reads;
                           dims > 3: pts.data is C-ordered float64 rows of dims */
    int dims;           /* the caller's columns (0 for an empty `[]`) */
} points_arg_t;

static void points_release(points_arg_t *p) {
    Py_CLEAR(p->arr);
}

/* Points of more than 3 coordinates: computed by _ndim.c, not the library. */
static int is_nd(const points_arg_t *p) {
    return p->dims > 3;
}

/* ------------------------------------------------------------------------
 * What an empty set gives: the library's policies (hd_empty_policy_t, their
 * names and values); the option's parsing and message live here.
 * EMPTY_NONE: the function has no such option (an empty set is an error).
 * ---------------------------------------------------------------------- */

typedef hd_empty_policy_t empty_t;
#define EMPTY_NONE ((empty_t)-1)

/* "'a', 'b' or 'c'" of the policies' names from `first` on. */
static void empty_list(empty_t first, char *buf, size_t size) {
    buf[0] = '\0';
    for (int k = (int)first; hd_empty_policy_name((empty_t)k); k++) {
        size_t used = strlen(buf);
        const char *sep = k == (int)first ? "" : hd_empty_policy_name((empty_t)(k + 1)) ? ", " : " or ";
        snprintf(buf + used, size - used, "%s'%s'", sep, hd_empty_policy_name((empty_t)k));
    }
}

static int parse_empty(const char *name, empty_t *out) {
    *out = HD_EMPTY_ERROR;
    if (!name || hd_empty_policy_from_name(name, out) == HD_OK) return 0;
    char known[128];
    empty_list(HD_EMPTY_ERROR, known, sizeof known);
    PyErr_Format(PyExc_ValueError, "empty must be %s, not '%s'", known, name);
    return -1;
}

/* The error for an empty set under `empty` (EMPTY_NONE or HD_EMPTY_ERROR). */
static void empty_error(const char *name, empty_t empty) {
    char known[128] = "";
    if (empty == HD_EMPTY_ERROR) empty_list(HD_EMPTY_INF, known, sizeof known);
    PyErr_Format(PyExc_ValueError, "%s is empty: at least one point is needed%s%s%s", name,
                 *known ? " (empty=" : "", known, *known ? " gives a value instead)" : "");
}

/* ------------------------------------------------------------------------
 * Shapes and coordinates.
 * ---------------------------------------------------------------------- */

/* An (N, c) array, c < 3, as the (N, 3) array of its points padded with
 * zeros, of dtype `want` (float32 or float64), C-ordered.  The padded
 * differences are 0, so every squared distance is the c-column sum plus
 * +0s, the same double: nothing is rounded on the way. */
static PyArrayObject *lift_to_3d(PyArrayObject *arr, int want) {
    PyArrayObject *src = (PyArrayObject *)PyArray_FromArray(
        arr, PyArray_DescrFromType(want),
        NPY_ARRAY_ALIGNED | NPY_ARRAY_NOTSWAPPED | NPY_ARRAY_FORCECAST);
    if (!src) return NULL;
    npy_intp dims[2] = {PyArray_DIM(src, 0), 3}, cols = PyArray_DIM(src, 1);
    PyArrayObject *out = (PyArrayObject *)PyArray_ZEROS(2, dims, want, 0);
    if (!out) {
        Py_DECREF(src);
        return NULL;
    }
    const char *s = PyArray_BYTES(src);
    npy_intp s0 = PyArray_STRIDE(src, 0), s1 = PyArray_STRIDE(src, 1);
    size_t el = want == NPY_DOUBLE ? sizeof(double) : sizeof(float);
    char *d = PyArray_BYTES(out);
    for (npy_intp k = 0; k < dims[0]; k++)
        for (npy_intp c = 0; c < cols; c++)
            memcpy(d + (size_t)(3 * k + c) * el, s + k * s0 + c * s1, el);
    Py_DECREF(src);
    return out;
}

/* "A" for "a": the library's name of a set in its messages. */
static char set_letter(const char *name) {
    return name[0] >= 'a' && name[0] <= 'z' && !name[1] ? (char)(name[0] - 'a' + 'A') : '?';
}

/* v as the shortest "%.Ng" text that reads back to the same double, so that
 * a coordinate just beyond a limit never prints equal to it. */
static void shortest_text(char *buf, size_t size, double v) {
    for (int digits = 1; digits <= 17; digits++) {
        snprintf(buf, size, "%.*g", digits, v);
        if (strtod(buf, NULL) == v) return;
    }
}

/* Points of dims > 3 coordinates (C-ordered doubles): the library's checks,
 * its messages and codes, with a limit that keeps the sum of dims squared
 * differences finite (1e153, the library's, while dims * (2e153)^2 fits). */
static int nd_check(const double *x, size_t n, size_t dims, const char *name) {
    double limit = sqrt(DBL_MAX / (4.0 * (double)dims));
    if (limit > HD_MAX_COORD) limit = HD_MAX_COORD;
    hd_error_t err;
    for (size_t k = 0; k < n * dims; k++) {
        double v = x[k];
        int code = !isfinite(v) ? HD_ENONFINITE : fabs(v) > limit ? HD_ERANGE : HD_OK;
        if (code == HD_OK) continue;
        memset(&err, 0, sizeof err);
        if (code == HD_ENONFINITE)
            snprintf(err.message, sizeof err.message, "point set %c: point %zu has %s coordinate",
                     set_letter(name), k / dims, isnan(v) ? "a NaN" : "an infinite");
        else {
            char vt[32], lt[32];
            shortest_text(vt, sizeof vt, v);
            shortest_text(lt, sizeof lt, limit);
            snprintf(err.message, sizeof err.message,
                     "point set %c: point %zu has coordinate %s, beyond the limit %s where "
                     "squared distances in %zu dimensions could overflow",
                     set_letter(name), k / dims, vt, lt, dims);
        }
        raise_hd(code, &err);
        return -1;
    }
    return 0;
}

/* The shape check: an (N, D) array with D >= 1, or an empty `[]`. */
static int shape_ok(PyArrayObject *arr, const char *name) {
    int nd = PyArray_NDIM(arr);
    if ((nd == 1 && PyArray_SIZE(arr) == 0) || (nd == 2 && PyArray_DIM(arr, 1) >= 1)) return 0;
    PyObject *shape = PyObject_GetAttrString((PyObject *)arr, "shape");
    if (shape) {
        PyErr_Format(PyExc_ValueError,
                     "%s must be an (N, D) array of N points of D >= 1 coordinates, got shape %R",
                     name, shape);
        Py_DECREF(shape);
    }
    return -1;
}

/* The dtype the library reads arr as: float32 and float64 stay, other real
 * numbers and booleans (0 and 1, as scipy computes with them) become
 * float64; -1 with a TypeError for anything else. */
static int wanted_type(PyArrayObject *arr, const char *name) {
    int type = PyArray_TYPE(arr);
    if (type == NPY_DOUBLE || type == NPY_FLOAT) return type;
    if (PyArray_ISINTEGER(arr) || PyArray_ISFLOAT(arr) || PyArray_ISBOOL(arr)) return NPY_DOUBLE;
    PyObject *s = PyObject_Str((PyObject *)PyArray_DESCR(arr));
    if (s) {
        PyErr_Format(PyExc_TypeError,
                     "%s must hold real numbers (float32, float64, integers or booleans), got %U",
                     name, s);
        Py_DECREF(s);
    }
    return -1;
}

/* Fill *out from an array of points, whose reference it takes (released on
 * failure).  `name` is the argument's name in messages.  An empty set is an
 * error unless a policy other than "error" is given; it is then returned
 * with count 0.  Returns 0, or -1 with an exception set. */
static int points_prepare(PyArrayObject *arr, const char *name, empty_t empty,
                          points_arg_t *out) {
    memset(out, 0, sizeof *out);
    int want;
    if (shape_ok(arr, name) || (want = wanted_type(arr, name)) < 0) {
        Py_DECREF(arr);
        return -1;
    }
    int cols = PyArray_NDIM(arr) == 2 ? (int)PyArray_DIM(arr, 1) : 0;
    out->dims = cols;
    if (cols == 0 || PyArray_DIM(arr, 0) == 0) {
        if (empty == EMPTY_NONE || empty == HD_EMPTY_ERROR) {
            empty_error(name, empty);
            Py_DECREF(arr);
            return -1;
        }
        out->arr = arr;
        out->pts.dtype = HD_FLOAT64;
        return 0; /* count 0 */
    }
    if (cols > 3) { /* C-ordered doubles for _ndim.c (float32 widens exactly) */
        PyArrayObject *c = (PyArrayObject *)PyArray_FromArray(
            arr, PyArray_DescrFromType(NPY_DOUBLE), NPY_ARRAY_CARRAY_RO | NPY_ARRAY_FORCECAST);
        Py_DECREF(arr);
        if (!c) return -1;
        out->arr = c;
        out->pts = (hd_points_t){PyArray_DATA(c), (size_t)PyArray_DIM(c, 0), HD_FLOAT64,
                                 (ptrdiff_t)(cols * sizeof(double)), (ptrdiff_t)sizeof(double)};
        if (nd_check(PyArray_DATA(c), out->pts.count, (size_t)cols, name)) {
            points_release(out);
            return -1;
        }
        return 0;
    }
    if (cols < 3) {
        PyArrayObject *c = lift_to_3d(arr, want);
        Py_DECREF(arr);
        if (!c) return -1;
        arr = c;
    }
    npy_intp s0 = PyArray_STRIDE(arr, 0), s1 = PyArray_STRIDE(arr, 1);
    /* The library reads a zero stride as "packed": materialise broadcasts. */
    int zero_stride = s1 == 0 || (s0 == 0 && PyArray_DIM(arr, 0) > 1);
    if (want != PyArray_TYPE(arr) || !PyArray_ISNOTSWAPPED(arr) || !PyArray_ISALIGNED(arr) ||
        zero_stride) {
        PyArrayObject *c = (PyArrayObject *)PyArray_FromArray(
            arr, PyArray_DescrFromType(want), NPY_ARRAY_CARRAY | NPY_ARRAY_FORCECAST);
        Py_DECREF(arr);
        if (!c) return -1;
        arr = c;
        s0 = PyArray_STRIDE(arr, 0);
        s1 = PyArray_STRIDE(arr, 1);
    }
    out->arr = arr;
    out->pts.data = PyArray_DATA(arr);
    out->pts.count = (size_t)PyArray_DIM(arr, 0);
    out->pts.dtype = PyArray_TYPE(arr) == NPY_FLOAT ? HD_FLOAT32 : HD_FLOAT64;
    out->pts.stride = (ptrdiff_t)s0;
    out->pts.cstride = (ptrdiff_t)s1;
    return 0;
}

/* One set from any array-like. */
static int points_from_object(PyObject *obj, const char *name, empty_t empty,
                              points_arg_t *out) {
    memset(out, 0, sizeof *out);
    PyArrayObject *arr = (PyArrayObject *)PyArray_FROM_O(obj);
    if (!arr) return -1;
    return points_prepare(arr, name, empty, out);
}

/* Both sets of a two-set call, which must have the same number of columns
 * (scipy's rule, and its words); on failure neither is held. */
static int points_pair(PyObject *oa, PyObject *ob, empty_t empty, points_arg_t *a,
                       points_arg_t *b) {
    memset(a, 0, sizeof *a);
    memset(b, 0, sizeof *b);
    PyArrayObject *xa = (PyArrayObject *)PyArray_FROM_O(oa);
    if (!xa) return -1;
    PyArrayObject *xb = (PyArrayObject *)PyArray_FROM_O(ob);
    if (!xb) {
        Py_DECREF(xa);
        return -1;
    }
    if (PyArray_NDIM(xa) == 2 && PyArray_NDIM(xb) == 2 && PyArray_DIM(xa, 1) != PyArray_DIM(xb, 1)) {
        PyErr_Format(PyExc_ValueError,
                     "a and b need to have the same number of columns, got %zd and %zd",
                     (Py_ssize_t)PyArray_DIM(xa, 1), (Py_ssize_t)PyArray_DIM(xb, 1));
        Py_DECREF(xa);
        Py_DECREF(xb);
        return -1;
    }
    if (points_prepare(xa, "a", empty, a)) {
        Py_DECREF(xb);
        return -1;
    }
    if (points_prepare(xb, "b", empty, b)) {
        points_release(a);
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------------------------
 * Options.
 * ---------------------------------------------------------------------- */

/* Any integer: an int, a numpy integer, anything with __index__.  A new
 * reference, or NULL with a TypeError naming the option. */
static PyObject *as_integer(PyObject *obj, const char *name, const char *what) {
    PyObject *v = PyNumber_Index(obj);
    if (!v && PyErr_ExceptionMatches(PyExc_TypeError)) {
        PyErr_Clear();
        PyErr_Format(PyExc_TypeError, "%s must be %s, not %.100s", name, what,
                     Py_TYPE(obj)->tp_name);
    }
    return v;
}

/* threads: None or 0 = every core, else a positive count. */
static int parse_threads(PyObject *obj, int *threads) {
    *threads = 0;
    if (!obj || obj == Py_None) return 0;
    PyObject *i = as_integer(obj, "threads", "None or an integer");
    if (!i) return -1;
    int overflow;
    long v = PyLong_AsLongAndOverflow(i, &overflow);
    Py_DECREF(i);
    if (v == -1 && PyErr_Occurred()) return -1;
    if (overflow || v < 0 || v > INT_MAX) {
        PyErr_Format(PyExc_ValueError,
                     "threads must be None (every core) or a positive number, not %R", obj);
        return -1;
    }
    *threads = (int)v;
    return 0;
}

/* numpy's random generator objects (numpy.random's Generator, RandomState,
 * BitGenerator, SeedSequence): scipy's directed_hausdorff takes them as its
 * seed.  1 when obj is one, 0 when not, -1 with an exception set. */
static int is_numpy_random(PyObject *obj) {
    static const char *const names[] = {"Generator", "RandomState", "BitGenerator", "SeedSequence"};
    PyObject *mod = PyImport_ImportModule("numpy.random");
    if (!mod) return -1;
    int found = 0;
    for (size_t k = 0; !found && k < sizeof names / sizeof names[0]; k++) {
        PyObject *type = PyObject_GetAttrString(mod, names[k]);
        if (!type) {
            PyErr_Clear(); /* an older numpy without it */
            continue;
        }
        found = PyObject_IsInstance(obj, type);
        Py_DECREF(type);
    }
    Py_DECREF(mod);
    return found;
}

/* seed (or scipy 1.15's rng): it orders the randomised algorithms' work and
 * never changes the answer, so every form scipy takes is accepted: None
 * (the default seed), any integer (its value modulo 2**64, negative and
 * huge ones included), and a numpy random generator, which gives the default
 * seed and is left untouched (nothing is drawn from it). */
static int parse_seed(PyObject *seed, uint64_t *out) {
    if (!seed || seed == Py_None) return 0;
    int gen = PyIndex_Check(seed) ? 0 : is_numpy_random(seed);
    if (gen) return gen < 0 ? -1 : 0;
    PyObject *i = as_integer(seed, "seed", "None, an integer or a numpy random generator");
    if (!i) return -1;
    unsigned long long s = PyLong_AsUnsignedLongLongMask(i);
    Py_DECREF(i);
    if (s == (unsigned long long)-1 && PyErr_Occurred()) return -1;
    *out = (uint64_t)s;
    return 0;
}

static int parse_options(const char *algorithm, PyObject *threads, PyObject *seed,
                         hd_options_t *opt) {
    hd_options_init(opt);
    if (algorithm && hd_algorithm_from_name(algorithm, &opt->algorithm) != HD_OK) {
        char known[256] = "";
        for (int k = 0; k < HD__ALG_COUNT; k++) {
            size_t used = strlen(known);
            snprintf(known + used, sizeof known - used, "%s%s", k ? ", " : "",
                     hd_algorithm_name((hd_algorithm_t)k));
        }
        PyErr_Format(PyExc_ValueError, "unknown algorithm '%s' (known: %s)", algorithm, known);
        return -1;
    }
    if (parse_threads(threads, &opt->threads)) return -1;
    return parse_seed(seed, &opt->seed);
}

/* rotation (3x3) and translation (3,), either may be None.  *use is 0 when
 * both are None (no transform at all). */
static int parse_transform(PyObject *rotation, PyObject *translation, hd_transform_t *T,
                           int *use) {
    hd_transform_identity(T);
    *use = 0;
    struct {
        PyObject *obj;
        const char *name;
        double *dst;
        int n;
    } parts[2] = {{rotation, "rotation", T->r, 9}, {translation, "translation", T->t, 3}};
    for (int k = 0; k < 2; k++) {
        if (!parts[k].obj || parts[k].obj == Py_None) continue;
        PyArrayObject *a = (PyArrayObject *)PyArray_FROM_OTF(
            parts[k].obj, NPY_DOUBLE, NPY_ARRAY_CARRAY | NPY_ARRAY_FORCECAST);
        if (!a) return -1;
        int ok = parts[k].n == 9
                     ? PyArray_NDIM(a) == 2 && PyArray_DIM(a, 0) == 3 && PyArray_DIM(a, 1) == 3
                     : PyArray_NDIM(a) == 1 && PyArray_DIM(a, 0) == 3;
        if (!ok) {
            PyErr_Format(PyExc_ValueError, "%s must have shape %s", parts[k].name,
                         parts[k].n == 9 ? "(3, 3)" : "(3,)");
            Py_DECREF(a);
            return -1;
        }
        const double *v = PyArray_DATA(a);
        for (int c = 0; c < parts[k].n; c++) {
            if (!isfinite(v[c])) {
                PyErr_Format(PyExc_ValueError, "%s must be finite", parts[k].name);
                Py_DECREF(a);
                return -1;
            }
            parts[k].dst[c] = v[c];
        }
        Py_DECREF(a);
        *use = 1;
    }
    return 0;
}

/* ------------------------------------------------------------------------
 * Result types.
 * ---------------------------------------------------------------------- */

static PyTypeObject DirectedResultType, HausdorffResultType;

static PyStructSequence_Field directed_fields[] = {
    {"distance", "the directed Hausdorff distance h(A, B)"},
    {"i", "witness: index in A (smallest on ties)"},
    {"j", "witness: index in B nearest to A[i] (smallest on ties)"},
    {"algorithm", "the algorithm that actually ran"},
    {"seconds", "wall-clock time of the computation"},
    {"distance_evals", "point-to-point distances evaluated"},
    {NULL, NULL},
};

static PyStructSequence_Desc directed_desc = {
    "hausdorff.DirectedResult",
    "The directed distance h(A, B) and its witness, a 3-tuple (distance, i, j) "
    "as scipy.spatial.distance.directed_hausdorff returns; also has the "
    "attributes algorithm, seconds and distance_evals.",
    directed_fields,
    3,
};

static PyStructSequence_Field hausdorff_fields[] = {
    {"distance", "the Hausdorff distance H(A, B) = max(h(A, B), h(B, A))"},
    {"ab", "h(A, B) as a DirectedResult: ab.i indexes A, ab.j indexes B"},
    {"ba", "h(B, A) as a DirectedResult: ba.i indexes B, ba.j indexes A"},
    {"alpha", "overlap degree of the bounding boxes (0 apart or touching, 1 full)"},
    {"disjoint", "True when the bounding boxes do not intersect"},
    {"seconds", "wall-clock time of both directions"},
    {NULL, NULL},
};

static PyStructSequence_Desc hausdorff_desc = {
    "hausdorff.HausdorffResult",
    "The symmetric distance H(A, B) with both directions, a 3-tuple "
    "(distance, ab, ba); also has the attributes alpha, disjoint and seconds.",
    hausdorff_fields,
    3,
};

static PyTypeObject PercentileResultType;

static PyStructSequence_Field percentile_fields[] = {
    {"p", "the percentile asked for, in [0, 100]"},
    {"ab", "p-th percentile of the distances of A's points to B"},
    {"ba", "p-th percentile of the distances of B's points to A"},
    {"symmetric", "max(ab, ba): MONAI's percentile Hausdorff distance (HD95)"},
    {"pooled", "p-th percentile of both directions' distances together: medpy's hd95"},
    {NULL, NULL},
};

static PyStructSequence_Desc percentile_desc = {
    "hausdorff.PercentileResult",
    "Percentile Hausdorff distances: the tuple (p, ab, ba, symmetric, pooled).",
    percentile_fields,
    5,
};

/* A struct sequence of `type` holding v[0..n), whose references it steals;
 * NULL (with the exception set) when any of them is NULL. */
static PyObject *struct_of(PyTypeObject *type, PyObject **v, int n) {
    PyObject *o = PyStructSequence_New(type);
    int bad = !o;
    for (int k = 0; k < n; k++) {
        if (!v[k]) bad = 1;
        if (o) PyStructSequence_SET_ITEM(o, k, v[k]); /* NULL is fine for dealloc */
        else Py_XDECREF(v[k]);
    }
    if (bad) Py_CLEAR(o);
    return o;
}

static PyObject *percentile_result(const hd_percentile_t *r) {
    PyObject *v[5] = {PyFloat_FromDouble(r->p), PyFloat_FromDouble(r->ab),
                      PyFloat_FromDouble(r->ba), PyFloat_FromDouble(r->symmetric),
                      PyFloat_FromDouble(r->pooled)};
    return struct_of(&PercentileResultType, v, 5);
}

static PyObject *directed_result(const hd_result_t *r) {
    PyObject *v[6] = {
        PyFloat_FromDouble(r->distance),
        PyLong_FromSize_t(r->i),
        PyLong_FromSize_t(r->j),
        PyUnicode_FromString(hd_algorithm_name(r->algorithm)),
        PyFloat_FromDouble(r->seconds),
        PyLong_FromUnsignedLongLong(r->stats.distance_evals),
    };
    return struct_of(&DirectedResultType, v, 6);
}

static PyObject *hausdorff_result(const hd_symmetric_t *r) {
    PyObject *v[6] = {
        PyFloat_FromDouble(r->distance),
        directed_result(&r->ab),
        directed_result(&r->ba),
        PyFloat_FromDouble(r->alpha),
        PyBool_FromLong(r->disjoint),
        PyFloat_FromDouble(r->seconds),
    };
    return struct_of(&HausdorffResultType, v, 6);
}

/* The results of a call with an empty set: every distance is the policy's
 * value v, and there is no witness (None), algorithm or box overlap. */
static PyObject *directed_empty(double v) {
    Py_INCREF(Py_None);
    Py_INCREF(Py_None);
    Py_INCREF(Py_None);
    PyObject *f[6] = {PyFloat_FromDouble(v), Py_None, Py_None, Py_None,
                      PyFloat_FromDouble(0.0), PyLong_FromLong(0)};
    return struct_of(&DirectedResultType, f, 6);
}

static PyObject *hausdorff_empty(double v) {
    Py_INCREF(Py_None);
    PyObject *f[6] = {PyFloat_FromDouble(v), directed_empty(v), directed_empty(v),
                      PyFloat_FromDouble(NAN), Py_None, PyFloat_FromDouble(0.0)};
    return struct_of(&HausdorffResultType, f, 6);
}

/* Sums, means and Chamfer distances: hd_summary_t field for field. */
static PyTypeObject SummaryType, MeanResultType;

static PyStructSequence_Field summary_fields[] = {
    {"n_ab", "number of distances from A's points to B (len(a))"},
    {"n_ba", "number of distances from B's points to A (len(b); 0 when directed)"},
    {"max_ab", "h(A, B), the largest distance of A's points to B"},
    {"max_ba", "h(B, A)"},
    {"sum_ab", "sum of the distances of A's points to B (correctly rounded)"},
    {"sum_ba", "sum of the distances of B's points to A"},
    {"sum2_ab", "sum of the squared distances of A's points to B"},
    {"sum2_ba", "sum of the squared distances of B's points to A"},
    {"mean_ab", "mean distance of A's points to B"},
    {"mean_ba", "mean distance of B's points to A"},
    {"mean2_ab", "mean squared distance of A's points to B"},
    {"mean2_ba", "mean squared distance of B's points to A"},
    {"mean_symmetric", "max(mean_ab, mean_ba): the average Hausdorff distance"},
    {"mean_average", "(mean_ab + mean_ba) / 2"},
    {"mean_pooled", "math.fsum of both sets' distances / (n_ab + n_ba): MONAI's symmetric "
                    "average surface distance, medpy's assd"},
    {"chamfer", "mean2_ab + mean2_ba: the Chamfer distance (as PyTorch3D)"},
    {"chamfer_sum2", "math.fsum of both sets' squared distances"},
    {"chamfer_mean", "mean_ab + mean_ba: point-cloud-utils' chamfer_distance"},
    {"chamfer_sum", "math.fsum of both sets' distances"},
    {NULL, NULL},
};

static PyStructSequence_Desc summary_desc = {
    "hausdorff.Summary",
    "Sums, means and Chamfer distances of the per-point distances, the same "
    "doubles as the command line's --mean and --chamfer (the fields of the C "
    "library's hd_summary_t).  Fields of B's direction are NaN when directed.",
    summary_fields,
    19,
};

static PyStructSequence_Field mean_fields[] = {
    {"ab", "mean distance of A's points to B"},
    {"ba", "mean distance of B's points to A"},
    {"symmetric", "max(ab, ba): the average Hausdorff distance"},
    {"average", "(ab + ba) / 2"},
    {"pooled", "mean of both directions' distances together (MONAI's symmetric ASD, medpy's assd)"},
    {NULL, NULL},
};

static PyStructSequence_Desc mean_desc = {
    "hausdorff.MeanResult",
    "Mean distances, the tuple (ab, ba, symmetric, average, pooled): the "
    "command line's --mean.",
    mean_fields,
    5,
};

static PyObject *summary_result(const hd_summary_t *s) {
    const double d[17] = {s->max_ab, s->max_ba, s->sum_ab, s->sum_ba, s->sum2_ab, s->sum2_ba,
                          s->mean_ab, s->mean_ba, s->mean2_ab, s->mean2_ba, s->mean_symmetric,
                          s->mean_average, s->mean_pooled, s->chamfer, s->chamfer_sum2,
                          s->chamfer_mean, s->chamfer_sum};
    PyObject *v[19];
    v[0] = PyLong_FromSize_t(s->n_ab);
    v[1] = PyLong_FromSize_t(s->n_ba);
    for (int k = 0; k < 17; k++) v[2 + k] = PyFloat_FromDouble(d[k]);
    return struct_of(&SummaryType, v, 19);
}

static PyObject *mean_result(const hd_summary_t *s) {
    PyObject *v[5] = {PyFloat_FromDouble(s->mean_ab), PyFloat_FromDouble(s->mean_ba),
                      PyFloat_FromDouble(s->mean_symmetric), PyFloat_FromDouble(s->mean_average),
                      PyFloat_FromDouble(s->mean_pooled)};
    return struct_of(&MeanResultType, v, 5);
}

/* ------------------------------------------------------------------------
 * Per-point distances: the query set against an index.
 * ---------------------------------------------------------------------- */

/* (dist, nearest) for every point of A against idx, with the GIL released
 * around the library call. */
static PyObject *nearest_arrays(const hd_index_t *idx, const hd_points_t *A,
                                const hd_transform_t *T, const hd_options_t *opt) {
    npy_intp n = (npy_intp)A->count;
    PyArrayObject *dist = (PyArrayObject *)PyArray_SimpleNew(1, &n, NPY_DOUBLE);
    PyArrayObject *nearest = (PyArrayObject *)PyArray_SimpleNew(1, &n, NPY_INTP);
    if (!dist || !nearest) {
        Py_XDECREF(dist);
        Py_XDECREF(nearest);
        return NULL;
    }
    hd_error_t err;
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = hd_index_nearest(idx, A, T, opt, (double *)PyArray_DATA(dist),
                          (size_t *)PyArray_DATA(nearest), &err);
    Py_END_ALLOW_THREADS
    if (rc != HD_OK) {
        Py_DECREF(dist);
        Py_DECREF(nearest);
        return raise_hd(rc, &err);
    }
    return Py_BuildValue("(NN)", dist, nearest);
}

/* ------------------------------------------------------------------------
 * Module functions.
 * ---------------------------------------------------------------------- */

PyDoc_STRVAR(directed_doc,
"directed($module, a, b, seed=0, *, rng=None, algorithm='auto', threads=None,\n"
"         empty='error')\n--\n\n"
"The directed Hausdorff distance h(a, b) = max over p in a of min over q in b\n"
"of |p - q|, exact to the last bit, with its witness.\n"
"\n"
"A drop-in for scipy.spatial.distance.directed_hausdorff(u, v, rng=0): the\n"
"same calls (seed positional or keyword, None included; scipy's names u= and\n"
"v= for a and b, scipy 1.15's rng= for seed) return the tuple\n"
"(distance, i, j) where |a[i] - b[j]| == distance, the same double as\n"
"scipy's.  On ties i is the smallest index in a whose nearest distance is\n"
"the maximum and j the smallest index in b at that distance, for every\n"
"algorithm, seed and thread count (scipy's witness depends on its random\n"
"order instead).\n"
"\n"
"a, b: (N, D) array-likes of real numbers or booleans (as 0 and 1), both\n"
"    with the same number D >= 1 of coordinates.  The squared distance is\n"
"    the sum of the squared differences from the first coordinate to the\n"
"    last, and the distance its sqrt, as a brute force (and scipy) computes\n"
"    them.  D = 1 and 2 are computed as the points padded with zeros to 3-D,\n"
"    which changes no distance; D >= 4 by the module's own exact engine.\n"
"    float32 and float64 (N, 3) arrays are read in place (C or Fortran\n"
"    order or strided views); other dtypes are converted to float64.\n"
"seed, rng: they never change the answer, only the order the randomised\n"
"    algorithms (earlybreak, ohd) visit points in: None (the default seed),\n"
"    any integer (its value modulo 2**64), or a numpy random generator\n"
"    (Generator, RandomState, BitGenerator, SeedSequence), which is left\n"
"    untouched.  Give one of the two.\n"
"algorithm: 'auto' (the fastest exact engine), 'naive', 'earlybreak',\n"
"    'inc', 'nohd', 'ohd', 'framework' or 'kdtree'; with D >= 4 'auto',\n"
"    'earlybreak' or 'naive'.\n"
"threads: None or 0 for every core, else the number of threads.\n"
"empty: what an empty set gives: 'error' (ValueError), 'inf', 'nan',\n"
"    'zero', 'monai' (inf when one set is empty, NaN when both are) or\n"
"    'skimage' (inf when one set is empty, 0 when both are); the witness is\n"
"    then (None, None).\n"
"\n"
"The GIL is released during the computation.  Raises ValueError for a wrong\n"
"shape, an empty set, NaN or infinite coordinates, or an unknown algorithm.\n"
"\n"
">>> import numpy as np, hausdorff\n"
">>> a = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])\n"
">>> b = np.array([[0.0, 0, 0.5], [1, 0.25, 0]])\n"
">>> d, i, j = hausdorff.directed(a, b)\n"
">>> print(round(d, 6), i, j)\n"
"1.118034 2 0\n"
">>> hausdorff.directed(a, b).distance == d\n"
"True\n"
">>> hausdorff.directed(u=[(0, 0), (3, 4)], v=[(0, 0)], rng=1)\n"
"hausdorff.DirectedResult(distance=5.0, i=1, j=0)\n"
">>> hausdorff.directed([[0, 0, 0, 0]], [[1, 1, 1, 1]]).distance\n"
"2.0\n"
">>> hausdorff.directed(a, np.empty((0, 3)), empty='inf').distance\n"
"inf\n");

/* scipy's names for directed()'s parameters: u and v for a and b, and
 * scipy 1.15's rng for seed.  aliases[first..] apply to the function
 * `fname`; *out is kw with them renamed (a new reference; NULL when kw is
 * NULL).  Giving both names of one parameter is a TypeError, as scipy's
 * "only one may be specified" for seed and rng. */
static int scipy_names(PyObject *kw, int first, const char *fname, PyObject **out) {
    static const char *const alias[3][3] = {
        {"u", "a", "scipy's name for it"}, {"v", "b", "scipy's name for it"},
        {"rng", "seed", "scipy 1.15's name for it"}};
    *out = NULL;
    if (!kw) return 0;
    PyObject *copy = NULL;
    for (int k = first; k < 3; k++) {
        PyObject *val = PyDict_GetItemString(kw, alias[k][0]);
        if (!val) continue;
        if (PyDict_GetItemString(kw, alias[k][1])) {
            PyErr_Format(PyExc_TypeError, "%s() got both '%s' and '%s' (%s)", fname, alias[k][1],
                         alias[k][0], alias[k][2]);
            Py_XDECREF(copy);
            return -1;
        }
        if (!copy && !(copy = PyDict_Copy(kw))) return -1;
        if (PyDict_SetItemString(copy, alias[k][1], val) < 0 ||
            PyDict_DelItemString(copy, alias[k][0]) < 0) {
            Py_DECREF(copy);
            return -1;
        }
    }
    if (!copy) {
        Py_INCREF(kw);
        copy = kw;
    }
    *out = copy;
    return 0;
}

/* The algorithms of points of more than 3 coordinates: 'auto' and
 * 'earlybreak' run _ndim.c's early break, 'naive' its brute force; the
 * others are the library's 3-D engines.  *early is 1 for the early break. */
static int nd_algorithm(const char *algorithm, int dims, int *early) {
    *early = strcmp(algorithm, "naive") != 0;
    if (!*early || !strcmp(algorithm, "auto") || !strcmp(algorithm, "earlybreak")) return 0;
    PyErr_Format(PyExc_ValueError,
                 "algorithm '%s' computes in 3 dimensions; points of %d coordinates take "
                 "'auto', 'earlybreak' or 'naive'", algorithm, dims);
    return -1;
}

static double now_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The library's thread count of opt->threads (0: every core). */
static int resolve_threads(int threads) {
    if (threads > 0) return threads;
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)(n < 64 ? n : 64) : 1;
}

/* h(a, b) of points of more than 3 coordinates, as the library's
 * hd_result_t; -1 with MemoryError when _ndim.c had no memory. */
static int nd_directed_result(const points_arg_t *a, const points_arg_t *b, int early,
                              const hd_options_t *opt, hd_result_t *r) {
    nd_directed_t x;
    int rc, threads = resolve_threads(opt->threads);
    double t0 = now_seconds();
    Py_BEGIN_ALLOW_THREADS
    rc = nd_directed(a->pts.data, a->pts.count, b->pts.data, b->pts.count, (size_t)a->dims,
                     early, opt->seed, threads, &x);
    Py_END_ALLOW_THREADS
    if (rc) {
        PyErr_NoMemory();
        return -1;
    }
    memset(r, 0, sizeof *r);
    r->distance = sqrt(x.d2);
    r->i = x.i;
    r->j = x.j;
    r->algorithm = early ? HD_ALG_EARLYBREAK : HD_ALG_NAIVE;
    r->seconds = now_seconds() - t0;
    r->stats.distance_evals = x.distance_evals;
    return 0;
}

/* The boxes' overlap of points of more than 3 coordinates: hd_overlap's
 * definition (hausdorff.h) with a factor per coordinate. */
static void nd_overlap(const points_arg_t *a, const points_arg_t *b, double *alpha,
                       int *disjoint) {
    const double *x[2] = {a->pts.data, b->pts.data};
    size_t n[2] = {a->pts.count, b->pts.count}, dims = (size_t)a->dims;
    *alpha = 1.0;
    *disjoint = 0;
    for (size_t c = 0; c < dims; c++) {
        double lo[2], hi[2];
        for (int s = 0; s < 2; s++) {
            lo[s] = hi[s] = x[s][c];
            for (size_t k = 1; k < n[s]; k++) {
                double v = x[s][k * dims + c];
                if (v < lo[s]) lo[s] = v;
                if (v > hi[s]) hi[s] = v;
            }
        }
        double ilo = lo[0] > lo[1] ? lo[0] : lo[1], ihi = hi[0] < hi[1] ? hi[0] : hi[1];
        double m = fmin(hi[0] - lo[0], hi[1] - lo[1]);
        if (ihi < ilo) *disjoint = 1;
        *alpha *= ihi < ilo ? 0.0 : m == 0.0 ? 1.0 : (ihi - ilo) / m;
    }
    if (*disjoint) *alpha = 0.0;
}

/* H(a, b) of points of more than 3 coordinates, as hd_symmetric_t. */
static int nd_symmetric_result(const points_arg_t *a, const points_arg_t *b, int early,
                               const hd_options_t *opt, hd_symmetric_t *h) {
    memset(h, 0, sizeof *h);
    if (nd_directed_result(a, b, early, opt, &h->ab) || nd_directed_result(b, a, early, opt, &h->ba))
        return -1;
    h->distance = h->ab.distance > h->ba.distance ? h->ab.distance : h->ba.distance;
    h->seconds = h->ab.seconds + h->ba.seconds;
    nd_overlap(a, b, &h->alpha, &h->disjoint);
    return 0;
}

/* directed() and hausdorff(): one computation, one or both directions. */
static PyObject *distance_call(PyObject *args, PyObject *kw, int symmetric) {
    static char *kw_directed[] = {"a", "b", "seed", "algorithm", "threads", "empty", NULL};
    static char *kw_hausdorff[] = {"a", "b", "algorithm", "threads", "seed", "empty", NULL};
    PyObject *oa, *ob, *threads = Py_None, *seed = NULL, *kw2;
    const char *algorithm = "auto", *empty_name = NULL;
    int ok;
    if (scipy_names(kw, symmetric ? 2 : 0, symmetric ? "hausdorff" : "directed", &kw2))
        return NULL;
    if (symmetric)
        ok = PyArg_ParseTupleAndKeywords(args, kw2, "OO|$sOOs:hausdorff", kw_hausdorff, &oa, &ob,
                                         &algorithm, &threads, &seed, &empty_name);
    else
        ok = PyArg_ParseTupleAndKeywords(args, kw2, "OO|O$sOs:directed", kw_directed, &oa, &ob,
                                         &seed, &algorithm, &threads, &empty_name);
    Py_XDECREF(kw2);
    if (!ok) return NULL;
    hd_options_t opt;
    empty_t empty;
    if (parse_options(algorithm, threads, seed, &opt) || parse_empty(empty_name, &empty))
        return NULL;
    points_arg_t a, b;
    if (points_pair(oa, ob, empty, &a, &b)) return NULL;
    size_t na = a.pts.count, nb = b.pts.count;
    if (!na || !nb) {
        points_release(&a);
        points_release(&b);
        double v = hd_empty_value(empty, na, nb);
        return symmetric ? hausdorff_empty(v) : directed_empty(v);
    }
    hd_result_t r;
    hd_symmetric_t h;
    hd_error_t err;
    int rc = HD_OK, early;
    if (is_nd(&a)) {
        if (nd_algorithm(algorithm, a.dims, &early) ||
            (symmetric ? nd_symmetric_result(&a, &b, early, &opt, &h)
                       : nd_directed_result(&a, &b, early, &opt, &r))) {
            points_release(&a);
            points_release(&b);
            return NULL;
        }
    } else {
        Py_BEGIN_ALLOW_THREADS
        rc = symmetric ? hd_hausdorff(&a.pts, &b.pts, &opt, &h, &err)
                       : hd_directed(&a.pts, &b.pts, &opt, &r, &err);
        Py_END_ALLOW_THREADS
    }
    points_release(&a);
    points_release(&b);
    if (rc != HD_OK) return raise_hd(rc, &err);
    return symmetric ? hausdorff_result(&h) : directed_result(&r);
}

static PyObject *py_directed(PyObject *self, PyObject *args, PyObject *kw) {
    (void)self;
    return distance_call(args, kw, 0);
}

PyDoc_STRVAR(hausdorff_doc,
"hausdorff($module, a, b, *, algorithm='auto', threads=None, seed=0, rng=None,\n"
"          empty='error')\n--\n\n"
"The Hausdorff distance H(a, b) = max(h(a, b), h(b, a)), exact, with the\n"
"witnesses of both directions.\n"
"\n"
"Returns a HausdorffResult, the tuple (distance, ab, ba): ab is h(a, b) as\n"
"a DirectedResult (ab.i indexes a, ab.j indexes b) and ba is h(b, a)\n"
"(ba.i indexes b, ba.j indexes a).  It also carries alpha (the overlap\n"
"degree of the bounding boxes), disjoint and seconds.  Arguments as for\n"
"directed(); with an empty set and an empty policy, both directions are\n"
"the policy's value, alpha is NaN and disjoint None.\n"
"\n"
">>> import numpy as np, hausdorff\n"
">>> a = np.array([[0.0, 0, 0], [1, 0, 0]])\n"
">>> b = np.array([[0.0, 0, 0], [3, 0, 0]])\n"
">>> d, ab, ba = hausdorff.hausdorff(a, b)\n"
">>> d, tuple(ab), tuple(ba)\n"
"(2.0, (1.0, 1, 0), (2.0, 1, 1))\n");

static PyObject *py_hausdorff(PyObject *self, PyObject *args, PyObject *kw) {
    (void)self;
    return distance_call(args, kw, 1);
}

PyDoc_STRVAR(distances_doc,
"distances($module, a, b, *, threads=None, empty='error')\n--\n\n"
"Per-point distances from a to b: for every point a[k], the exact distance\n"
"to its nearest point in b and that point's index (the smallest on ties).\n"
"\n"
"Returns (dist, nearest): a float64 and an intp array of len(a).\n"
"dist.max() is h(a, b).  To query b many times, build an Index(b) once.\n"
"With an empty b and an empty policy (see directed()), every distance is\n"
"the policy's value and every nearest index -1, as the command line's\n"
"--distances files; an empty a gives two empty arrays.\n"
"\n"
">>> import numpy as np, hausdorff\n"
">>> a = np.array([[0.0, 0, 0], [2, 0, 0]])\n"
">>> b = np.array([[0.0, 0, 1], [2, 0, 0.5]])\n"
">>> dist, nearest = hausdorff.distances(a, b)\n"
">>> dist.tolist(), nearest.tolist()\n"
"([1.0, 0.5], [0, 1])\n");

static PyObject *py_distances(PyObject *self, PyObject *args, PyObject *kw) {
    (void)self;
    static char *kwlist[] = {"a", "b", "threads", "empty", NULL};
    PyObject *oa, *ob, *threads = Py_None;
    const char *empty_name = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|$Os:distances", kwlist, &oa, &ob,
                                     &threads, &empty_name))
        return NULL;
    hd_options_t opt;
    empty_t empty;
    if (parse_options(NULL, threads, NULL, &opt) || parse_empty(empty_name, &empty))
        return NULL;
    points_arg_t a, b;
    if (points_pair(oa, ob, empty, &a, &b)) return NULL;
    npy_intp n = (npy_intp)a.pts.count;
    PyArrayObject *dist = (PyArrayObject *)PyArray_SimpleNew(1, &n, NPY_DOUBLE);
    PyArrayObject *nearest = (PyArrayObject *)PyArray_SimpleNew(1, &n, NPY_INTP);
    PyObject *res = NULL;
    if (dist && nearest && (!a.pts.count || !b.pts.count)) {
        double v = hd_empty_value(empty, a.pts.count, b.pts.count);
        for (npy_intp k = 0; k < n; k++) {
            ((double *)PyArray_DATA(dist))[k] = v;
            ((npy_intp *)PyArray_DATA(nearest))[k] = -1;
        }
        res = Py_BuildValue("(OO)", dist, nearest);
    } else if (dist && nearest) {
        hd_error_t err;
        int rc;
        double *d = PyArray_DATA(dist);
        size_t *k = PyArray_DATA(nearest);
        Py_BEGIN_ALLOW_THREADS
        if (is_nd(&a))
            rc = nd_nearest(a.pts.data, a.pts.count, b.pts.data, b.pts.count, (size_t)a.dims,
                            resolve_threads(opt.threads), d, k) ? HD_ENOMEM : HD_OK;
        else
            rc = hd_distances(&a.pts, &b.pts, &opt, d, k, NULL, NULL, &err);
        Py_END_ALLOW_THREADS
        if (rc == HD_OK) res = Py_BuildValue("(OO)", dist, nearest);
        else raise_hd(rc, is_nd(&a) ? NULL : &err);
    }
    Py_XDECREF(dist);
    Py_XDECREF(nearest);
    points_release(&a);
    points_release(&b);
    return res;
}

/* The per-point distances of both directions (only a's when directed), as
 * the command line computes them for its analysis options: d_ab and d_ba
 * are PyMem_Raw blocks the caller frees.  The sets must not be empty. */
static int both_distances(const points_arg_t *a, const points_arg_t *b, int directed,
                          const hd_options_t *opt, double **d_ab, double **d_ba) {
    size_t na = a->pts.count, nb = b->pts.count;
    *d_ab = PyMem_RawMalloc(na * sizeof(double));
    *d_ba = directed ? NULL : PyMem_RawMalloc(nb * sizeof(double));
    if (!*d_ab || (!directed && !*d_ba)) {
        PyErr_NoMemory();
        return -1;
    }
    hd_error_t err;
    int rc;
    Py_BEGIN_ALLOW_THREADS
    if (is_nd(a)) {
        int threads = resolve_threads(opt->threads);
        size_t dims = (size_t)a->dims;
        rc = nd_nearest(a->pts.data, na, b->pts.data, nb, dims, threads, *d_ab, NULL) ||
                     (!directed && nd_nearest(b->pts.data, nb, a->pts.data, na, dims, threads, *d_ba, NULL))
                 ? HD_ENOMEM : HD_OK;
    } else {
        rc = hd_distances(&a->pts, &b->pts, opt, *d_ab, NULL, *d_ba, NULL, &err);
    }
    Py_END_ALLOW_THREADS
    if (rc != HD_OK) {
        raise_hd(rc, is_nd(a) ? NULL : &err);
        return -1;
    }
    return 0;
}

PyDoc_STRVAR(percentile_doc,
"percentile($module, a, b, p, *, threads=None, empty='error')\n--\n\n"
"Percentile Hausdorff distances, e.g. HD95 with p=95, exact.\n"
"\n"
"p is a number in [0, 100] or a sequence of them (the per-point distances\n"
"are then computed once for all).  For each p the result is a\n"
"PercentileResult (p, ab, ba, symmetric, pooled): ab is the p-th percentile\n"
"of the distances of a's points to b, ba of b's points to a, both with\n"
"numpy's default linear interpolation (bit-identical to numpy.percentile);\n"
"symmetric = max(ab, ba) is MONAI's HD95; pooled, the percentile of both\n"
"directions' distances together, is medpy's hd95.  p=100 gives h(a, b),\n"
"h(b, a) and H(a, b).  A sequence p gives a list of results.  The same\n"
"doubles as the command line's --percentile.  With an empty set and an\n"
"empty policy (see directed()), all four figures are the policy's value.\n"
"\n"
">>> import numpy as np, hausdorff\n"
">>> a = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]])\n"
">>> b = np.array([[0.0, 0, 1], [1, 0, 0], [2, 0, 0]])\n"
">>> hausdorff.percentile(a, b, 100).symmetric\n"
"1.0\n"
">>> [r.ab for r in hausdorff.percentile(a, b, [0, 50, 75])]\n"
"[0.0, 0.0, 0.5]\n");

static PyObject *py_percentile(PyObject *self, PyObject *args, PyObject *kw) {
    (void)self;
    static char *kwlist[] = {"a", "b", "p", "threads", "empty", NULL};
    PyObject *oa, *ob, *op, *threads = Py_None;
    const char *empty_name = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OOO|$Os:percentile", kwlist, &oa, &ob, &op,
                                     &threads, &empty_name))
        return NULL;
    hd_options_t opt;
    empty_t empty;
    if (parse_options(NULL, threads, NULL, &opt) || parse_empty(empty_name, &empty))
        return NULL;
    PyArrayObject *parr = (PyArrayObject *)PyArray_FROM_OTF(
        op, NPY_DOUBLE, NPY_ARRAY_CARRAY | NPY_ARRAY_FORCECAST);
    if (!parr) return NULL;
    if (PyArray_NDIM(parr) > 1) {
        Py_DECREF(parr);
        PyErr_SetString(PyExc_ValueError, "p must be a number or a 1-D sequence of numbers");
        return NULL;
    }
    int scalar = PyArray_NDIM(parr) == 0;
    size_t np_ = (size_t)PyArray_SIZE(parr);
    const double *p = PyArray_DATA(parr);
    hd_error_t err;
    /* Check every p with the library's own rule before the long part. */
    double one = 0.0, *scratch = PyMem_Malloc((np_ ? np_ : 1) * sizeof(double));
    if (!scratch) {
        Py_DECREF(parr);
        return PyErr_NoMemory();
    }
    int rc = hd_percentiles(&one, 1, p, np_, scratch, &err);
    PyMem_Free(scratch);
    if (rc != HD_OK) {
        Py_DECREF(parr);
        return raise_hd(rc, &err);
    }
    points_arg_t a, b;
    if (points_pair(oa, ob, empty, &a, &b)) {
        Py_DECREF(parr);
        return NULL;
    }
    size_t na = a.pts.count, nb = b.pts.count;
    double *d_ab = NULL, *d_ba = NULL;
    hd_percentile_t *res = PyMem_RawMalloc((np_ ? np_ : 1) * sizeof *res);
    PyObject *out = NULL;
    if (!res) {
        PyErr_NoMemory();
        goto done;
    }
    if (!na || !nb) {
        double v = hd_empty_value(empty, na, nb);
        for (size_t k = 0; k < np_; k++) res[k] = (hd_percentile_t){p[k], v, v, v, v};
    } else if (np_ == 1 && !is_nd(&a)) { /* one percentile: without every distance */
        Py_BEGIN_ALLOW_THREADS
        rc = hd_hausdorff_percentile(&a.pts, &b.pts, &opt, p[0], &res[0], &err);
        Py_END_ALLOW_THREADS
        if (rc != HD_OK) {
            raise_hd(rc, &err);
            goto done;
        }
    } else {
        if (both_distances(&a, &b, 0, &opt, &d_ab, &d_ba)) goto done;
        Py_BEGIN_ALLOW_THREADS
        for (size_t k = 0; rc == HD_OK && k < np_; k++)
            rc = hd_percentile_of(d_ab, na, d_ba, nb, p[k], &res[k], &err);
        Py_END_ALLOW_THREADS
        if (rc != HD_OK) {
            raise_hd(rc, &err);
            goto done;
        }
    }
    if (scalar) {
        out = percentile_result(&res[0]);
        goto done;
    }
    out = PyList_New((Py_ssize_t)np_);
    for (size_t k = 0; out && k < np_; k++) {
        PyObject *r = percentile_result(&res[k]);
        if (!r) Py_CLEAR(out);
        else PyList_SET_ITEM(out, (Py_ssize_t)k, r);
    }
done:
    PyMem_RawFree(d_ab);
    PyMem_RawFree(d_ba);
    PyMem_RawFree(res);
    Py_DECREF(parr);
    points_release(&a);
    points_release(&b);
    return out;
}

/* summary(), mean() and chamfer(): hd_distances, then hd_summarize, as the
 * command line's --mean and --chamfer.  With an empty set every figure is
 * the policy's value (NaN for B's direction when directed), as the command
 * line's --empty reports them. */
enum { WANT_SUMMARY, WANT_MEAN, WANT_CHAMFER };

static PyObject *summary_call(PyObject *args, PyObject *kw, int want) {
    static char *kw_summary[] = {"a", "b", "directed", "threads", "empty", NULL};
    static char *kw_other[] = {"a", "b", "threads", "empty", NULL};
    PyObject *oa, *ob, *threads = Py_None;
    const char *empty_name = NULL;
    int directed = 0, ok;
    if (want == WANT_SUMMARY)
        ok = PyArg_ParseTupleAndKeywords(args, kw, "OO|$pOs:summary", kw_summary, &oa, &ob,
                                         &directed, &threads, &empty_name);
    else
        ok = PyArg_ParseTupleAndKeywords(args, kw,
                                         want == WANT_MEAN ? "OO|$Os:mean" : "OO|$Os:chamfer",
                                         kw_other, &oa, &ob, &threads, &empty_name);
    if (!ok) return NULL;
    hd_options_t opt;
    empty_t empty;
    if (parse_options(NULL, threads, NULL, &opt) || parse_empty(empty_name, &empty))
        return NULL;
    points_arg_t a, b;
    if (points_pair(oa, ob, empty, &a, &b)) return NULL;
    size_t na = a.pts.count, nb = b.pts.count;
    hd_summary_t s;
    PyObject *out = NULL;
    double *d_ab = NULL, *d_ba = NULL;
    if (!na || !nb) {
        double v = hd_empty_value(empty, na, nb), w = directed ? NAN : v;
        s = (hd_summary_t){na, directed ? 0 : nb, v, w, v, w, v, w, v, w, v, w,
                           w, w, w, w, w, w, w};
    } else {
        if (both_distances(&a, &b, directed, &opt, &d_ab, &d_ba)) goto done;
        hd_error_t err;
        int rc = hd_summarize(d_ab, na, d_ba, directed ? 0 : nb, &s, &err);
        if (rc != HD_OK) {
            raise_hd(rc, &err);
            goto done;
        }
    }
    out = want == WANT_SUMMARY ? summary_result(&s)
          : want == WANT_MEAN  ? mean_result(&s)
                               : PyFloat_FromDouble(s.chamfer);
done:
    PyMem_RawFree(d_ab);
    PyMem_RawFree(d_ba);
    points_release(&a);
    points_release(&b);
    return out;
}

PyDoc_STRVAR(summary_doc,
"summary($module, a, b, *, directed=False, threads=None, empty='error')\n--\n\n"
"Every sum, mean and Chamfer distance of the per-point distances, as a\n"
"Summary: the same doubles as the command line's --mean and --chamfer (the\n"
"C library's hd_summarize).  Sums are correctly rounded (math.fsum's\n"
"result, whatever the order), so the same at any thread count.  directed=True computes\n"
"only a's distances to b (B's fields are NaN and n_ba is 0), as the command\n"
"line's --directed; its Chamfer figure is then mean2_ab.  With an empty set\n"
"and an empty policy (see directed()), every figure is the policy's value.\n"
"\n"
">>> import numpy as np, hausdorff\n"
">>> a = np.array([[0.0, 0, 0], [2, 0, 0]])\n"
">>> b = np.array([[0.0, 0, 1]])\n"
">>> s = hausdorff.summary(a, b)\n"
">>> s.mean_ab, s.mean_ba, s.chamfer, s.n_ab, s.n_ba\n"
"(1.618033988749895, 1.0, 4.0, 2, 1)\n");

static PyObject *py_summary(PyObject *self, PyObject *args, PyObject *kw) {
    (void)self;
    return summary_call(args, kw, WANT_SUMMARY);
}

PyDoc_STRVAR(mean_doc,
"mean($module, a, b, *, threads=None, empty='error')\n--\n\n"
"Mean distances, the command line's --mean: a MeanResult (ab, ba,\n"
"symmetric, average, pooled) where ab is the mean distance of a's points to\n"
"b, ba of b's points to a, symmetric = max(ab, ba) (the average Hausdorff\n"
"distance), average = (ab + ba) / 2 and pooled the mean of all the\n"
"distances of both directions together (MONAI's symmetric average surface\n"
"distance, and medpy's assd, which averages both lists of distances\n"
"together).  Empty sets as for directed().\n"
"\n"
">>> import numpy as np, hausdorff\n"
">>> a = np.array([[0.0, 0, 0], [2, 0, 0]])\n"
">>> b = np.array([[0.0, 0, 1]])\n"
">>> tuple(hausdorff.mean(a, b))[:2]\n"
"(1.618033988749895, 1.0)\n");

static PyObject *py_mean(PyObject *self, PyObject *args, PyObject *kw) {
    (void)self;
    return summary_call(args, kw, WANT_MEAN);
}

PyDoc_STRVAR(chamfer_doc,
"chamfer($module, a, b, *, threads=None, empty='error')\n--\n\n"
"The Chamfer distance, the command line's --chamfer: the mean squared\n"
"distance of a's points to b plus the mean squared distance of b's points\n"
"to a (as PyTorch3D's chamfer_distance).  summary() has the summed and the\n"
"unsquared variants; point-cloud-utils' chamfer_distance, the sum of the\n"
"two mean (unsquared) distances, is summary(a, b).chamfer_mean, not this.\n"
"Empty sets as for directed().\n"
"\n"
">>> import hausdorff\n"
">>> hausdorff.chamfer([[0.0, 0, 0], [2, 0, 0]], [[0.0, 0, 1]])\n"
"4.0\n");

static PyObject *py_chamfer(PyObject *self, PyObject *args, PyObject *kw) {
    (void)self;
    return summary_call(args, kw, WANT_CHAMFER);
}

/* ------------------------------------------------------------------------
 * Reading files.
 * ---------------------------------------------------------------------- */

static void cloud_capsule_free(PyObject *capsule) {
    hd_cloud_free(PyCapsule_GetPointer(capsule, "hausdorff.cloud"));
}

PyDoc_STRVAR(read_doc,
"read($module, path, *, format=None, float32=False, decimal_comma=False,\n"
"     start=0, count=None)\n--\n\n"
"Read a point cloud with the library's readers and return it as an (N, 3)\n"
"array, float64 by default or float32 with float32=True.\n"
"\n"
"The format comes from the extension (confirmed by the file's magic) unless\n"
"format names it (one of hausdorff.formats()).  Mesh formats give their\n"
"vertices.  Text files whose numbers have decimal commas (1,5;2,5;3,5) are\n"
"refused unless decimal_comma=True, which reads commas as decimal points\n"
"and ';' or blanks as separators.\n"
"start and count read points [start, start + count) only (count None: to\n"
"the end); both are integers of any kind (int, numpy integers, __index__),\n"
"start >= 0 and count >= 1, below 2**64; LAS, LAZ, NPY and binary\n"
"PLY/PCD/STL then touch only those\n"
"records, so processes can share one big file (hausdorff.count gives its\n"
"size from the header).  A range past the end raises ValueError.\n"
"The array takes over the memory the reader filled: no copy.\n"
"Raises OSError when the file cannot be read and ValueError when it is\n"
"malformed, empty or of an unknown format.\n"
"\n"
">>> import hausdorff, os, tempfile\n"
">>> path = os.path.join(tempfile.mkdtemp(), 'two.xyz')\n"
">>> with open(path, 'w') as f:\n"
"...     _ = f.write('0 0 0\\n1 2 3\\n')\n"
">>> hausdorff.read(path).tolist()\n"
"[[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]]\n");

/* A count or position given to read(): any integer (int, numpy integer,
 * __index__) from `least` (0 or 1) below 2**64; a float or another type is
 * a TypeError, anything out of range a ValueError naming the value. */
static int parse_u64(PyObject *obj, const char *name, int least, unsigned long long *out) {
    const char *what = least ? "a positive integer" : "a non-negative integer";
    PyObject *i = as_integer(obj, name, what);
    if (!i) return -1;
    int overflow;
    long long v = PyLong_AsLongLongAndOverflow(i, &overflow);
    unsigned long long u = 0;
    int ok = 0;
    if (overflow > 0) { /* at least 2**63 */
        u = PyLong_AsUnsignedLongLong(i);
        ok = !(u == (unsigned long long)-1 && PyErr_Occurred());
        PyErr_Clear();
    } else if (!overflow && !(v == -1 && PyErr_Occurred())) {
        u = (unsigned long long)v;
        ok = v >= least;
    }
    if (!ok && !PyErr_Occurred())
        PyErr_Format(PyExc_ValueError, "%s must be %s below 2**64, not %S", name, what, i);
    Py_DECREF(i);
    *out = u;
    return ok ? 0 : -1;
}

static PyObject *py_read(PyObject *self, PyObject *args, PyObject *kw) {
    (void)self;
    static char *kwlist[] = {"path", "format", "float32", "decimal_comma", "start", "count", NULL};
    PyObject *path = NULL, *start_obj = NULL, *count_obj = Py_None;
    const char *format = NULL;
    int float32 = 0, decimal_comma = 0;
    unsigned long long start = 0, count = 0;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O&|$zppOO:read", kwlist, PyUnicode_FSConverter,
                                     &path, &format, &float32, &decimal_comma, &start_obj,
                                     &count_obj))
        return NULL;
    if ((start_obj && parse_u64(start_obj, "read: start", 0, &start)) ||
        (count_obj != Py_None && parse_u64(count_obj, "read: count", 1, &count))) {
        Py_DECREF(path);
        return NULL;
    }
    hd_read_options_t ropt;
    hd_read_options_init(&ropt);
    ropt.format = format;
    ropt.decimal_comma = decimal_comma;
    ropt.dtype = float32 ? HD_FLOAT32 : HD_FLOAT64;
    const char *cpath = PyBytes_AS_STRING(path);
    hd_cloud_t *cloud = NULL;
    hd_error_t err;
    int rc = HD_OK;
    uint64_t total = 0;
    if (start && count_obj == Py_None) {
        /* to the end: the header's count, else a whole read, cut below */
        Py_BEGIN_ALLOW_THREADS
        rc = hd_read_count(cpath, &ropt, &total, &err);
        if (rc == HD_EUNSUPPORTED && (rc = hd_read_file(cpath, &ropt, &cloud, &err)) == HD_OK) total = cloud->count;
        Py_END_ALLOW_THREADS
        if (rc == HD_OK && start >= total) {
            PyErr_Format(PyExc_ValueError, "%s: start %llu is not below the file's %llu points", cpath, start,
                         (unsigned long long)total);
            hd_cloud_free(cloud);
            Py_DECREF(path);
            return NULL;
        }
        count = total - start;
    }
    if (rc == HD_OK && cloud) { /* read whole: keep [start, total) */
        size_t el = cloud->dtype == HD_FLOAT32 ? 3 * sizeof(float) : 3 * sizeof(double);
        memmove(cloud->data, (char *)cloud->data + (size_t)start * el, (size_t)count * el);
        cloud->count = (size_t)count;
    } else if (rc == HD_OK) {
        ropt.range_first = start;
        ropt.range_count = count; /* 0 with start 0: the whole file */
        Py_BEGIN_ALLOW_THREADS
        rc = hd_read_file(cpath, &ropt, &cloud, &err);
        Py_END_ALLOW_THREADS
    }
    Py_DECREF(path);
    if (rc != HD_OK) return raise_hd(rc, &err);
    npy_intp dims[2] = {(npy_intp)cloud->count, 3};
    PyObject *capsule = PyCapsule_New(cloud, "hausdorff.cloud", cloud_capsule_free);
    if (!capsule) {
        hd_cloud_free(cloud);
        return NULL;
    }
    PyObject *arr = PyArray_SimpleNewFromData(
        2, dims, cloud->dtype == HD_FLOAT32 ? NPY_FLOAT : NPY_DOUBLE, cloud->data);
    if (!arr) {
        Py_DECREF(capsule);
        return NULL;
    }
    if (PyArray_SetBaseObject((PyArrayObject *)arr, capsule) < 0) { /* steals capsule */
        Py_DECREF(arr);
        return NULL;
    }
    return arr;
}

PyDoc_STRVAR(write_field_doc,
"write_field($module, in_path, out_path, values, *, name=None,\n"
"            farther_than=None, nearer_than=None, format=None,\n"
"            decimal_comma=False)\n--\n\n"
"Write out_path: the points of in_path in its own format (PLY ascii or\n"
"binary, LAS, LAZ, xyz/csv/pts text; OBJ subsets) with\n"
"values[k] added to point k as the field `name` ('distance' when not\n"
"given: a PLY vertex property, a\n"
"LAS/LAZ extra-bytes dimension, a text column); every other property,\n"
"element, record and line of the input is kept.  values: one float per\n"
"point, as read(in_path) numbers them; or a dict {name: values} for\n"
"several fields written in one pass, in the dict's order (then `name` is\n"
"not given).  With farther_than=D only the\n"
"points whose value (the first field's) is > D are written, with\n"
"nearer_than=D those <= D\n"
"(in the input's format, the fields included); name='' writes no field.\n"
"out_path's extension must name the input's format.  Returns the number\n"
"of points written.  The file appears whole or not at all.  Raises\n"
"ValueError (bad arguments, a name the input already has, a format that\n"
"cannot hold the field) and OSError (out_path cannot be written).\n"
"The library's hd_write_field and hd_write_fields; formats:\n"
"docs/formats.md.\n\n"
">>> import os, tempfile, hausdorff\n"
">>> d = tempfile.mkdtemp()\n"
">>> src = os.path.join(d, 'a.xyz')\n"
">>> _ = open(src, 'w').write('0 0 0\\n1 0 0\\n')\n"
">>> hausdorff.write_field(src, os.path.join(d, 'far.xyz'), [0.5, 2.0], farther_than=1.0)\n"
"1\n"
">>> print(open(os.path.join(d, 'far.xyz')).read(), end='')\n"
"1 0 0 2\n"
">>> hausdorff.write_field(src, os.path.join(d, 'two.xyz'), {'distance': [0.5, 2.0], 'nearest': [1, 0]})\n"
"2\n"
">>> print(open(os.path.join(d, 'two.xyz')).read(), end='')\n"
"0 0 0 0.5 1\n"
"1 0 0 2 0\n");

/* values as a one-dimensional array of doubles (a new reference), or NULL
 * with the exception set. */
static PyArrayObject *field_values(PyObject *values, const char *name) {
    PyArrayObject *v = (PyArrayObject *)PyArray_FROM_OTF(values, NPY_DOUBLE, NPY_ARRAY_IN_ARRAY);
    if (v && PyArray_NDIM(v) != 1) {
        PyErr_Format(PyExc_ValueError, "write_field: the values of '%s' must be one-dimensional (one per point), not "
                                       "of shape with %d dimensions",
                     name, PyArray_NDIM(v));
        Py_DECREF(v);
        return NULL;
    }
    return v;
}

/* The fields of values (a dict: its items in order; else one array named
 * name) into f[], their arrays (new references) into arr[]; their count,
 * or -1 with the exception set (the arrays made so far in arr[]). */
static Py_ssize_t write_fields_of(PyObject *values, const char *name, hd_field_t *f, PyArrayObject **arr,
                                  Py_ssize_t cap, size_t *n) {
    if (!PyDict_Check(values)) {
        if (!(arr[0] = field_values(values, name))) return -1;
        f[0].name = name, f[0].values = (const double *)PyArray_DATA(arr[0]);
        *n = (size_t)PyArray_DIM(arr[0], 0);
        return 1;
    }
    PyObject *key, *val;
    Py_ssize_t pos = 0, k = 0;
    while (k < cap && PyDict_Next(values, &pos, &key, &val)) {
        const char *kname = PyUnicode_Check(key) ? PyUnicode_AsUTF8(key) : NULL;
        if (!kname) {
            if (!PyErr_Occurred()) PyErr_SetString(PyExc_TypeError, "write_field: the fields' names must be str");
            return -1;
        }
        if (!(arr[k] = field_values(val, kname))) return -1;
        f[k].name = kname, f[k].values = (const double *)PyArray_DATA(arr[k]);
        size_t m = (size_t)PyArray_DIM(arr[k], 0);
        if (k && m != *n) {
            PyErr_Format(PyExc_ValueError, "write_field: '%s' has %zu values, '%s' %zu", kname, m, f[0].name, *n);
            return -1;
        }
        *n = m;
        k++;
    }
    return k;
}

static PyObject *py_write_field(PyObject *self, PyObject *args, PyObject *kw) {
    (void)self;
    static char *kwlist[] = {"in_path", "out_path", "values", "name", "farther_than", "nearer_than", "format",
                             "decimal_comma", NULL};
    PyObject *in = NULL, *out = NULL, *values = NULL, *far = Py_None, *near = Py_None;
    const char *name = NULL, *format = NULL;
    int decimal_comma = 0;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O&O&O|$sOOzp:write_field", kwlist, PyUnicode_FSConverter, &in,
                                     PyUnicode_FSConverter, &out, &values, &name, &far, &near, &format, &decimal_comma)) {
        Py_XDECREF(in);
        Py_XDECREF(out);
        return NULL;
    }
    hd_write_options_t wo;
    hd_write_options_init(&wo);
    int several = PyDict_Check(values);
    PyObject *own = several ? PyDict_Copy(values) : NULL; /* its keys name the fields while the GIL is released */
    if (several && !own) {
        Py_DECREF(in);
        Py_DECREF(out);
        return NULL;
    }
    if (own) values = own;
    Py_ssize_t nf = several ? PyDict_Size(values) : 1, made = 0;
    hd_field_t *f = PyMem_Calloc((size_t)nf + 1, sizeof *f);
    PyArrayObject **arr = PyMem_Calloc((size_t)nf + 1, sizeof *arr);
    size_t n = 0;
    if (!f || !arr) {
        PyErr_NoMemory();
        goto fail;
    }
    if (several && name) {
        PyErr_SetString(PyExc_ValueError, "write_field: with a dict of fields their names are its keys, not name=");
        goto fail;
    }
    if (several && nf == 0) {
        PyErr_SetString(PyExc_ValueError, "write_field: the dict of fields is empty");
        goto fail;
    }
    if (far != Py_None && near != Py_None) {
        PyErr_SetString(PyExc_ValueError, "write_field: give farther_than or nearer_than, not both");
        goto fail;
    }
    if (far != Py_None || near != Py_None) {
        wo.keep = far != Py_None ? HD_KEEP_FARTHER : HD_KEEP_NEARER;
        wo.threshold = PyFloat_AsDouble(far != Py_None ? far : near);
        if (wo.threshold == -1.0 && PyErr_Occurred()) goto fail;
    }
    made = write_fields_of(values, name ? name : "distance", f, arr, nf, &n);
    if (made < 0) goto fail;
    wo.name = f[0].name;
    hd_read_options_t ro;
    hd_read_options_init(&ro);
    ro.format = format;
    ro.decimal_comma = decimal_comma;
    wo.read = &ro;
    hd_error_t err;
    size_t written = 0;
    int rc;
    const char *ci = PyBytes_AS_STRING(in), *co = PyBytes_AS_STRING(out);
    Py_BEGIN_ALLOW_THREADS
    rc = several ? hd_write_fields(ci, co, f, (size_t)made, n, &wo, &written, &err)
                 : hd_write_field(ci, co, f[0].values, n, &wo, &written, &err);
    Py_END_ALLOW_THREADS
    for (Py_ssize_t k = 0; k < nf; k++) Py_XDECREF(arr[k]);
    PyMem_Free(arr);
    PyMem_Free(f);
    Py_XDECREF(own);
    Py_DECREF(in);
    Py_DECREF(out);
    if (rc != HD_OK) return raise_hd(rc, &err);
    return PyLong_FromSize_t(written);
fail:
    for (Py_ssize_t k = 0; arr && k < nf; k++) Py_XDECREF(arr[k]);
    PyMem_Free(arr);
    PyMem_Free(f);
    Py_XDECREF(own);
    Py_DECREF(in);
    Py_DECREF(out);
    return NULL;
}

PyDoc_STRVAR(count_doc,
"count($module, path, *, format=None)\n--\n\n"
"The number of points read(path) would give, from the file's header alone,\n"
"for LAS, LAZ, NPY and binary PLY, PCD and STL.  Raises ValueError for the\n"
"other formats (their count needs the whole file read) and as read() does\n"
"for a bad header.\n");

static PyObject *py_count(PyObject *self, PyObject *args, PyObject *kw) {
    (void)self;
    static char *kwlist[] = {"path", "format", NULL};
    PyObject *path = NULL;
    const char *format = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O&|$z:count", kwlist, PyUnicode_FSConverter, &path, &format))
        return NULL;
    hd_read_options_t ropt;
    hd_read_options_init(&ropt);
    ropt.format = format;
    uint64_t n = 0;
    hd_error_t err;
    int rc;
    const char *cpath = PyBytes_AS_STRING(path);
    Py_BEGIN_ALLOW_THREADS
    rc = hd_read_count(cpath, &ropt, &n, &err);
    Py_END_ALLOW_THREADS
    Py_DECREF(path);
    if (rc != HD_OK) return raise_hd(rc, &err);
    return PyLong_FromUnsignedLongLong((unsigned long long)n);
}

PyDoc_STRVAR(formats_doc,
"formats($module, /)\n--\n\n"
"The names of the file formats read() knows, with a one-line description\n"
"of each, as a dict.\n");

static PyObject *py_formats(PyObject *self, PyObject *noargs) {
    (void)self;
    (void)noargs;
    PyObject *d = PyDict_New();
    if (!d) return NULL;
    for (const char *const *f = hd_formats(); *f; f++) {
        const char *desc = hd_format_description(*f);
        PyObject *v = PyUnicode_FromString(desc ? desc : "");
        if (!v || PyDict_SetItemString(d, *f, v) < 0) {
            Py_XDECREF(v);
            Py_DECREF(d);
            return NULL;
        }
        Py_DECREF(v);
    }
    return d;
}

/* ------------------------------------------------------------------------
 * Index.
 * ---------------------------------------------------------------------- */

typedef struct {
    PyObject_HEAD
    hd_index_t *idx;
    PyArrayObject *points; /* the index's own copy of b, never written */
    int dims;              /* b's columns: queries must have as many */
} IndexObject;

static PyTypeObject IndexType;

PyDoc_STRVAR(index_doc,
"Index(b, *, threads=None)\n--\n\n"
"An index of the point set b, built once and queried many times.\n"
"\n"
"The index keeps its own copy of b, so changing b afterwards does not\n"
"affect it; it is immutable, and any number of threads may query it at once.\n"
"Queries may move the query set by a rigid (or any affine) transform\n"
"x -> rotation @ x + translation, applied on the fly in double precision in\n"
"the order the C header documents, without copying the query.\n"
"An (N, 2) or (N, 1) b is indexed as its points padded with zeros to 3-D\n"
"(index.points has the three columns), and its queries must then have b's\n"
"columns too.  Points of 4 or more coordinates are refused (a transform is\n"
"3-D); directed(), hausdorff() and distances() take them.\n"
"\n"
">>> import numpy as np, hausdorff\n"
">>> index = hausdorff.Index(np.array([[0.0, 0, 0], [1, 0, 0]]))\n"
">>> len(index)\n"
"2\n"
">>> a = np.array([[0.0, 0, 2], [1, 0, 1]])\n"
">>> tuple(index.directed(a))\n"
"(2.0, 0, 0)\n"
">>> tuple(index.directed(a, translation=[0, 0, -1]))\n"
"(1.0, 0, 0)\n");

static void owner_capsule_free(PyObject *capsule) {
    PyObject *arr = PyCapsule_GetPointer(capsule, "hausdorff.owner");
    Py_XDECREF(arr);
}

/* A read-only array of arr's data, whose reference it takes, with a capsule
 * owning arr as its base.  numpy lets setflags(write=True) succeed only
 * when an array owns its data or its base chain ends in a writable buffer;
 * a capsule is neither, so the array can never be made writable, and arr,
 * reachable only through the capsule, is never written either. */
static PyArrayObject *read_only_view(PyArrayObject *arr) {
    PyObject *capsule = PyCapsule_New(arr, "hausdorff.owner", owner_capsule_free);
    if (!capsule) {
        Py_DECREF(arr);
        return NULL;
    }
    PyArray_Descr *descr = PyArray_DESCR(arr);
    Py_INCREF(descr);
    PyArrayObject *view = (PyArrayObject *)PyArray_NewFromDescr(
        &PyArray_Type, descr, PyArray_NDIM(arr), PyArray_DIMS(arr), PyArray_STRIDES(arr),
        PyArray_DATA(arr), 0 /* not writeable */, NULL);
    if (!view) {
        Py_DECREF(capsule);
        return NULL;
    }
    if (PyArray_SetBaseObject(view, capsule) < 0) { /* steals capsule */
        Py_DECREF(view);
        return NULL;
    }
    return view;
}

static PyObject *Index_new(PyTypeObject *type, PyObject *args, PyObject *kw) {
    static char *kwlist[] = {"b", "threads", NULL};
    PyObject *ob, *threads = Py_None;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O|$O:Index", kwlist, &ob, &threads))
        return NULL;
    hd_options_t opt;
    if (parse_options(NULL, threads, NULL, &opt)) return NULL;
    points_arg_t b;
    if (points_from_object(ob, "b", EMPTY_NONE, &b)) return NULL;
    int dims = b.dims;
    if (is_nd(&b)) {
        points_release(&b);
        PyErr_Format(PyExc_ValueError,
                     "Index takes points of 1, 2 or 3 coordinates (its queries move them by a 3-D "
                     "transform), got %d; directed(), hausdorff() and distances() take any", dims);
        return NULL;
    }
    /* Points of 1 or 2 coordinates were lifted into an array of our own already. */
    PyArrayObject *copy = dims < 3 ? b.arr : (PyArrayObject *)PyArray_NewCopy(b.arr, NPY_CORDER);
    if (dims < 3) b.arr = NULL;
    points_release(&b);
    PyArrayObject *own = copy ? read_only_view(copy) : NULL;
    if (!own) return NULL;
    IndexObject *self = (IndexObject *)type->tp_alloc(type, 0);
    if (!self) {
        Py_DECREF(own);
        return NULL;
    }
    self->points = own;
    self->dims = dims;
    self->idx = NULL;
    hd_points_t pts = {PyArray_DATA(own), (size_t)PyArray_DIM(own, 0),
                       PyArray_TYPE(own) == NPY_FLOAT ? HD_FLOAT32 : HD_FLOAT64, 0, 0};
    hd_error_t err;
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = hd_index_build(&pts, &opt, &self->idx, &err);
    Py_END_ALLOW_THREADS
    if (rc != HD_OK) {
        Py_DECREF(self);
        return raise_hd(rc, &err);
    }
    return (PyObject *)self;
}

static void Index_dealloc(IndexObject *self) {
    hd_index_free(self->idx);
    Py_XDECREF(self->points);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static Py_ssize_t Index_len(IndexObject *self) {
    return (Py_ssize_t)hd_index_count(self->idx);
}

/* Common argument parsing of the query methods. */
static int index_query_args(const IndexObject *self, PyObject *args, PyObject *kw,
                            const char *fmt, PyObject **oa, hd_transform_t *T, int *use_T,
                            hd_options_t *opt, points_arg_t *a) {
    static char *kwlist[] = {"a", "rotation", "translation", "threads", NULL};
    PyObject *rotation = Py_None, *translation = Py_None, *threads = Py_None;
    if (!PyArg_ParseTupleAndKeywords(args, kw, fmt, kwlist, oa, &rotation, &translation,
                                     &threads))
        return -1;
    if (parse_options(NULL, threads, NULL, opt)) return -1;
    if (parse_transform(rotation, translation, T, use_T)) return -1;
    if (points_from_object(*oa, "a", EMPTY_NONE, a)) return -1;
    if (a->dims != self->dims) {
        PyErr_Format(PyExc_ValueError,
                     "a and the indexed points need to have the same number of columns, "
                     "got %d and %d", a->dims, self->dims);
        points_release(a);
        return -1;
    }
    return 0;
}

PyDoc_STRVAR(index_directed_doc,
"directed($self, a, *, rotation=None, translation=None, threads=None)\n--\n\n"
"h(T(a), b), the directed distance from the transformed query to the indexed\n"
"set, with its witness (i indexes a, j indexes b), as a DirectedResult.\n"
"T(x) = rotation @ x + translation; either part may be omitted.\n");

static PyObject *Index_directed(IndexObject *self, PyObject *args, PyObject *kw) {
    PyObject *oa;
    hd_transform_t T;
    int use_T;
    hd_options_t opt;
    points_arg_t a;
    if (index_query_args(self, args, kw, "O|$OOO:directed", &oa, &T, &use_T, &opt, &a))
        return NULL;
    hd_result_t r;
    hd_error_t err;
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = hd_index_directed(self->idx, &a.pts, use_T ? &T : NULL, &opt, &r, &err);
    Py_END_ALLOW_THREADS
    points_release(&a);
    if (rc != HD_OK) return raise_hd(rc, &err);
    return directed_result(&r);
}

PyDoc_STRVAR(index_distances_doc,
"distances($self, a, *, rotation=None, translation=None, threads=None)\n--\n\n"
"Per-point distances from T(a) to the indexed set: (dist, nearest), a\n"
"float64 and an intp array of len(a); nearest is the smallest index at that\n"
"distance.  T(x) = rotation @ x + translation; either part may be omitted.\n");

static PyObject *Index_distances(IndexObject *self, PyObject *args, PyObject *kw) {
    PyObject *oa;
    hd_transform_t T;
    int use_T;
    hd_options_t opt;
    points_arg_t a;
    if (index_query_args(self, args, kw, "O|$OOO:distances", &oa, &T, &use_T, &opt, &a))
        return NULL;
    PyObject *res = nearest_arrays(self->idx, &a.pts, use_T ? &T : NULL, &opt);
    points_release(&a);
    return res;
}

static PyObject *Index_get_memory(IndexObject *self, void *closure) {
    (void)closure;
    return PyLong_FromSize_t(hd_index_memory(self->idx));
}

static PyObject *Index_get_points(IndexObject *self, void *closure) {
    (void)closure;
    Py_INCREF(self->points);
    return (PyObject *)self->points;
}

static PyObject *Index_repr(IndexObject *self) {
    return PyUnicode_FromFormat("<hausdorff.Index of %zu points, %s>",
                                hd_index_count(self->idx),
                                PyArray_TYPE(self->points) == NPY_FLOAT ? "float32" : "float64");
}

static PyMethodDef Index_methods[] = {
    {"directed", (PyCFunction)(void (*)(void))Index_directed, METH_VARARGS | METH_KEYWORDS,
     index_directed_doc},
    {"distances", (PyCFunction)(void (*)(void))Index_distances, METH_VARARGS | METH_KEYWORDS,
     index_distances_doc},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef Index_getset[] = {
    {"memory", (getter)Index_get_memory, NULL,
     "bytes the index allocated itself (not counting its copy of the points)", NULL},
    {"points", (getter)Index_get_points, NULL,
     "the indexed points: the index's own copy of b, read-only for good "
     "(setflags(write=True) raises)", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PySequenceMethods Index_as_sequence = {
    .sq_length = (lenfunc)Index_len,
};

static PyTypeObject IndexType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "hausdorff.Index",
    .tp_basicsize = sizeof(IndexObject),
    .tp_dealloc = (destructor)Index_dealloc,
    .tp_repr = (reprfunc)Index_repr,
    .tp_as_sequence = &Index_as_sequence,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = index_doc,
    .tp_methods = Index_methods,
    .tp_getset = Index_getset,
    .tp_new = Index_new,
};

/* ------------------------------------------------------------------------
 * Surfaces: points to a triangle mesh (hausdorff.Mesh in __init__.py).
 * ---------------------------------------------------------------------- */

/* faces: an (M, 3) array of non-negative integers, as a new C-ordered
 * uint64 array (NULL with the exception set). */
static PyArrayObject *faces_array(PyObject *obj) {
    PyArrayObject *raw = (PyArrayObject *)PyArray_FROM_O(obj);
    if (!raw) return NULL;
    if (PyArray_NDIM(raw) != 2 || PyArray_DIM(raw, 1) != 3 ||
        !(PyArray_ISINTEGER(raw) || PyArray_SIZE(raw) == 0)) {
        PyObject *shape = PyObject_GetAttrString((PyObject *)raw, "shape");
        if (shape)
            PyErr_Format(PyExc_ValueError, "faces must be an (M, 3) array of vertex indices (integers), got "
                                           "shape %R and dtype %R", shape, (PyObject *)PyArray_DESCR(raw));
        Py_XDECREF(shape);
        Py_DECREF(raw);
        return NULL;
    }
    PyArrayObject *i64 = (PyArrayObject *)PyArray_FromArray(raw, PyArray_DescrFromType(NPY_INT64),
                                                            NPY_ARRAY_CARRAY | NPY_ARRAY_FORCECAST);
    Py_DECREF(raw);
    if (!i64) return NULL;
    const int64_t *v = PyArray_DATA(i64);
    for (npy_intp k = 0; k < PyArray_SIZE(i64); k++)
        if (v[k] < 0) {
            PyErr_Format(PyExc_ValueError, "faces: face %zd refers to vertex %lld (indices start at 0)",
                         (Py_ssize_t)(k / 3), (long long)v[k]);
            Py_DECREF(i64);
            return NULL;
        }
    return i64; /* non-negative int64: the same bits as uint64 */
}

static PyObject *py_mesh_distances(PyObject *self, PyObject *args, PyObject *kw) {
    (void)self;
    static char *kwlist[] = {"points", "vertices", "faces", "threads", "signed", NULL};
    PyObject *op, *ov, *of, *threads = Py_None;
    int want_sign = 0;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OOO|$Op:_mesh_distances", kwlist, &op, &ov, &of, &threads,
                                     &want_sign))
        return NULL;
    hd_options_t opt;
    if (parse_options(NULL, threads, NULL, &opt)) return NULL;
    points_arg_t p, v;
    if (points_from_object(op, "points", HD_EMPTY_ERROR, &p)) return NULL;
    if (points_from_object(ov, "vertices", HD_EMPTY_ERROR, &v)) {
        points_release(&p);
        return NULL;
    }
    PyArrayObject *f = faces_array(of);
    npy_intp n = (npy_intp)p.pts.count, n3[2] = {n, 3};
    PyArrayObject *dist = NULL, *face = NULL, *closest = NULL, *bary = NULL, *sign = NULL;
    PyObject *res = NULL;
    if (f) {
        dist = (PyArrayObject *)PyArray_SimpleNew(1, &n, NPY_DOUBLE);
        face = (PyArrayObject *)PyArray_SimpleNew(1, &n, NPY_INTP);
        closest = (PyArrayObject *)PyArray_SimpleNew(2, n3, NPY_DOUBLE);
        bary = (PyArrayObject *)PyArray_SimpleNew(2, n3, NPY_DOUBLE);
        if (want_sign) sign = (PyArrayObject *)PyArray_SimpleNew(1, &n, NPY_INT8);
    }
    if (dist && face && closest && bary && (sign || !want_sign)) {
        hd_mesh_t M = {v.pts, PyArray_DATA(f), (size_t)PyArray_DIM(f, 0), HD_INDEX_U64};
        hd_surface_result_t r;
        hd_error_t err;
        int rc;
        Py_BEGIN_ALLOW_THREADS
        if (want_sign)
            rc = hd_mesh_signed_distances(&p.pts, &M, &opt, PyArray_DATA(dist), PyArray_DATA(face),
                                          PyArray_DATA(closest), PyArray_DATA(bary), PyArray_DATA(sign), &r, &err);
        else
            rc = hd_mesh_distances(&p.pts, &M, &opt, PyArray_DATA(dist), PyArray_DATA(face), PyArray_DATA(closest),
                                   PyArray_DATA(bary), &r, &err);
        Py_END_ALLOW_THREADS
        if (rc == HD_OK)
            res = Py_BuildValue("(OOOOdnnnO)", dist, face, closest, bary, r.distance, (Py_ssize_t)r.i,
                                (Py_ssize_t)r.triangle, (Py_ssize_t)r.n_degenerate,
                                sign ? (PyObject *)sign : Py_None);
        else
            raise_hd(rc, &err);
    }
    Py_XDECREF(dist);
    Py_XDECREF(face);
    Py_XDECREF(closest);
    Py_XDECREF(bary);
    Py_XDECREF(sign);
    Py_XDECREF(f);
    points_release(&p);
    points_release(&v);
    return res;
}

/* ------------------------------------------------------------------------
 * Surface to surface: enclosures (hausdorff.surface_hausdorff etc. in
 * _surface.py).
 * ---------------------------------------------------------------------- */

/* An enclosure as a tuple (lower, upper, tolerance, converged, face_a,
 * index_a, bary_a, point_a, witness_distance, witness_error, face_b,
 * index_b, point_b, faces_dropped, faces_split, kernel_calls, seconds);
 * SIZE_MAX indices as -1. */
static PyObject *enclosure_tuple(const hd_enclosure_t *e) {
#define HD__IX(v) ((v) == SIZE_MAX ? (Py_ssize_t)-1 : (Py_ssize_t)(v))
    return Py_BuildValue("(ddd" "Onn" "(ddd)(ddd)" "dd" "nn(ddd)" "KKKd)", e->lower, e->upper, e->tolerance,
                         e->converged ? Py_True : Py_False, HD__IX(e->face_a), HD__IX(e->index_a), e->bary_a[0],
                         e->bary_a[1], e->bary_a[2], e->point_a[0], e->point_a[1], e->point_a[2],
                         e->witness_distance, e->witness_error, HD__IX(e->face_b), HD__IX(e->index_b),
                         e->point_b[0], e->point_b[1], e->point_b[2], (unsigned long long)e->faces_dropped,
                         (unsigned long long)e->faces_split, (unsigned long long)e->kernel_calls, e->seconds);
#undef HD__IX
}

/* A mesh argument: its vertices and faces held until mesh_release. */
typedef struct mesh_arg {
    points_arg_t v;
    PyArrayObject *f;
    hd_mesh_t m;
} mesh_arg_t;

static void mesh_release(mesh_arg_t *m) {
    points_release(&m->v);
    Py_XDECREF(m->f);
    m->f = NULL;
}

static int mesh_from_objects(PyObject *ov, PyObject *of, const char *name, mesh_arg_t *out) {
    memset(out, 0, sizeof *out);
    if (points_from_object(ov, name, HD_EMPTY_ERROR, &out->v)) return -1;
    out->f = faces_array(of);
    if (!out->f) {
        points_release(&out->v);
        return -1;
    }
    hd_mesh_t m = {out->v.pts, PyArray_DATA(out->f), (size_t)PyArray_DIM(out->f, 0), HD_INDEX_U64};
    out->m = m;
    return 0;
}

static int surface_options(double tolerance, int relative, PyObject *threads, unsigned long long max_splits,
                           hd_surface_options_t *o) {
    hd_surface_options_init(o);
    o->tolerance = tolerance;
    o->relative = relative;
    o->max_splits = max_splits;
    return parse_threads(threads, &o->threads);
}

/* _surface_hausdorff(a_vertices, a_faces, b_vertices, b_faces, *, tolerance,
 * relative, threads, max_splits, directed, d, what): b_faces None makes B a
 * point set; what "hausdorff" -> (ab, ba or None), "within" -> (answer,
 * ab, ba), "faces" -> (face_lower, face_upper, ab). */
static PyObject *py_surface(PyObject *self, PyObject *args, PyObject *kw) {
    (void)self;
    static char *kwlist[] = {"a_vertices", "a_faces", "b_vertices", "b_faces", "tolerance", "relative",
                             "threads", "max_splits", "directed", "d", "what", NULL};
    PyObject *oav, *oaf, *obv, *obf, *threads = Py_None;
    double tolerance = 1e-9, d = 0;
    int relative = 1, directed = 0;
    unsigned long long max_splits = 1ull << 20;
    const char *what = "hausdorff";
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OOOO|$dpOKpds:_surface", kwlist, &oav, &oaf, &obv, &obf,
                                     &tolerance, &relative, &threads, &max_splits, &directed, &d, &what))
        return NULL;
    hd_surface_options_t o;
    if (surface_options(tolerance, relative, threads, max_splits, &o)) return NULL;
    mesh_arg_t a, b;
    memset(&b, 0, sizeof b);
    if (mesh_from_objects(oav, oaf, "A's vertices", &a)) return NULL;
    int points = obf == Py_None;
    int bad = points ? points_from_object(obv, "B", HD_EMPTY_ERROR, &b.v) : mesh_from_objects(obv, obf, "B's vertices", &b);
    if (bad) {
        mesh_release(&a);
        return NULL;
    }
    hd_enclosure_t ab, ba;
    hd_error_t err;
    int rc = HD_OK, answer = -1, faces = strcmp(what, "faces") == 0, within = strcmp(what, "within") == 0;
    PyArrayObject *lo = NULL, *hi = NULL;
    if (faces) {
        npy_intp n = (npy_intp)a.m.n_triangles;
        lo = (PyArrayObject *)PyArray_SimpleNew(1, &n, NPY_DOUBLE);
        hi = (PyArrayObject *)PyArray_SimpleNew(1, &n, NPY_DOUBLE);
        if (!lo || !hi) rc = HD_ENOMEM;
    }
    if (rc == HD_OK) {
        Py_BEGIN_ALLOW_THREADS
        if (faces) rc = hd_surface_face_maxima(&a.m, &b.m, &o, PyArray_DATA(lo), PyArray_DATA(hi), &ab, &err);
        else if (within) rc = hd_surface_within(&a.m, &b.m, d, directed, &o, &answer, &ab, &ba, &err);
        else if (points) rc = hd_surface_points_hausdorff(&a.m, &b.v.pts, &o, &ab, directed ? NULL : &ba, &err);
        else rc = hd_surface_hausdorff(&a.m, &b.m, &o, &ab, directed ? NULL : &ba, &err);
        Py_END_ALLOW_THREADS
    }
    PyObject *res = NULL;
    if (rc == HD_ENOMEM && faces && (!lo || !hi)) {
        if (!PyErr_Occurred()) PyErr_NoMemory();
    } else if (rc != HD_OK) {
        raise_hd(rc, &err);
    } else if (faces) {
        res = Py_BuildValue("(OON)", lo, hi, enclosure_tuple(&ab));
    } else {
        PyObject *pa = enclosure_tuple(&ab), *pb = NULL;
        if (directed && !within) {
            pb = Py_None;
            Py_INCREF(pb);
        } else {
            pb = enclosure_tuple(&ba);
        }
        res = within ? Py_BuildValue("(iNN)", answer, pa, pb) : Py_BuildValue("(NN)", pa, pb);
    }
    Py_XDECREF(lo);
    Py_XDECREF(hi);
    mesh_release(&a);
    mesh_release(&b);
    return res;
}

static PyObject *py_read_mesh(PyObject *self, PyObject *args, PyObject *kw) {
    (void)self;
    static char *kwlist[] = {"path", "format", NULL};
    PyObject *opath;
    const char *format = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O&|$z:_read_mesh", kwlist, PyUnicode_FSConverter, &opath, &format))
        return NULL;
    hd_read_options_t ro;
    hd_read_options_init(&ro);
    ro.format = format;
    hd_mesh_file_t *m = NULL;
    hd_error_t err;
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = hd_read_mesh(PyBytes_AS_STRING(opath), &ro, &m, &err);
    Py_END_ALLOW_THREADS
    Py_DECREF(opath);
    if (rc != HD_OK) return raise_hd(rc, &err);
    npy_intp dv[2] = {(npy_intp)m->n_vertices, 3}, dt[2] = {(npy_intp)m->n_triangles, 3};
    PyArrayObject *verts = (PyArrayObject *)PyArray_SimpleNew(2, dv, NPY_DOUBLE);
    PyArrayObject *faces = (PyArrayObject *)PyArray_SimpleNew(2, dt, NPY_INTP);
    PyObject *res = NULL;
    if (verts && faces) {
        memcpy(PyArray_DATA(verts), m->vertices, 3 * m->n_vertices * sizeof(double));
        npy_intp *o = PyArray_DATA(faces);
        for (size_t k = 0; k < 3 * m->n_triangles; k++) o[k] = (npy_intp)m->triangles[k];
        res = Py_BuildValue("(OOnns)", verts, faces, (Py_ssize_t)m->n_faces, (Py_ssize_t)m->n_degenerate, m->format);
    }
    Py_XDECREF(verts);
    Py_XDECREF(faces);
    hd_mesh_file_free(m);
    return res;
}

/* ------------------------------------------------------------------------
 * The module.
 * ---------------------------------------------------------------------- */

static PyMethodDef module_methods[] = {
    {"_mesh_distances", (PyCFunction)(void (*)(void))py_mesh_distances, METH_VARARGS | METH_KEYWORDS,
     "_mesh_distances(points, vertices, faces, *, threads=None, signed=False): hausdorff.Mesh.distances's engine"},
    {"_read_mesh", (PyCFunction)(void (*)(void))py_read_mesh, METH_VARARGS | METH_KEYWORDS,
     "_read_mesh(path, *, format=None): hausdorff.read_mesh's engine"},
    {"_surface", (PyCFunction)(void (*)(void))py_surface, METH_VARARGS | METH_KEYWORDS,
     "_surface(a_vertices, a_faces, b_vertices, b_faces, *, tolerance, relative, threads, max_splits, "
     "directed, d, what): the engine of hausdorff.surface_hausdorff, surface_within and face_maxima"},
    {"directed", (PyCFunction)(void (*)(void))py_directed, METH_VARARGS | METH_KEYWORDS,
     directed_doc},
    {"hausdorff", (PyCFunction)(void (*)(void))py_hausdorff, METH_VARARGS | METH_KEYWORDS,
     hausdorff_doc},
    {"distances", (PyCFunction)(void (*)(void))py_distances, METH_VARARGS | METH_KEYWORDS,
     distances_doc},
    {"percentile", (PyCFunction)(void (*)(void))py_percentile, METH_VARARGS | METH_KEYWORDS,
     percentile_doc},
    {"summary", (PyCFunction)(void (*)(void))py_summary, METH_VARARGS | METH_KEYWORDS,
     summary_doc},
    {"mean", (PyCFunction)(void (*)(void))py_mean, METH_VARARGS | METH_KEYWORDS, mean_doc},
    {"chamfer", (PyCFunction)(void (*)(void))py_chamfer, METH_VARARGS | METH_KEYWORDS,
     chamfer_doc},
    {"read", (PyCFunction)(void (*)(void))py_read, METH_VARARGS | METH_KEYWORDS, read_doc},
    {"formats", py_formats, METH_NOARGS, formats_doc},
    {"count", (PyCFunction)(void (*)(void))py_count, METH_VARARGS | METH_KEYWORDS, count_doc},
    {"write_field", (PyCFunction)(void (*)(void))py_write_field, METH_VARARGS | METH_KEYWORDS, write_field_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module_def = {
    PyModuleDef_HEAD_INIT,
    "hausdorff._hausdorff",
    "The C extension behind the hausdorff package (import hausdorff instead).",
    -1,
    module_methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__hausdorff(void) {
    import_array();
    struct {
        PyTypeObject *type;
        PyStructSequence_Desc *desc; /* NULL: a plain type */
    } types[] = {
        {&DirectedResultType, &directed_desc},
        {&HausdorffResultType, &hausdorff_desc},
        {&PercentileResultType, &percentile_desc},
        {&SummaryType, &summary_desc},
        {&MeanResultType, &mean_desc},
        {&IndexType, NULL},
    };
    const size_t n_types = sizeof types / sizeof types[0];
    for (size_t k = 0; k < n_types; k++) {
        int rc = types[k].desc ? (types[k].type->tp_name
                                      ? 0
                                      : PyStructSequence_InitType2(types[k].type, types[k].desc))
                               : PyType_Ready(types[k].type);
        if (rc < 0) return NULL;
    }
    PyObject *m = PyModule_Create(&module_def);
    if (!m) return NULL;
    for (size_t k = 0; k < n_types; k++) {
        /* "hausdorff.Index" -> "Index" */
        const char *name = strrchr(types[k].type->tp_name, '.') + 1;
        Py_INCREF(types[k].type);
        if (PyModule_AddObject(m, name, (PyObject *)types[k].type) < 0) {
            Py_DECREF(types[k].type);
            goto fail;
        }
    }
    PyObject *algorithms = PyTuple_New(HD__ALG_COUNT);
    if (!algorithms) goto fail;
    for (int k = 0; k < HD__ALG_COUNT; k++) {
        PyObject *name = PyUnicode_FromString(hd_algorithm_name((hd_algorithm_t)k));
        if (!name) {
            Py_DECREF(algorithms);
            goto fail;
        }
        PyTuple_SET_ITEM(algorithms, k, name);
    }
    if (PyModule_AddObject(m, "algorithms", algorithms) < 0) {
        Py_DECREF(algorithms);
        goto fail;
    }
    if (PyModule_AddStringConstant(m, "__version__", hd_version()) < 0) goto fail;
    if (PyModule_AddFunctions(m, hd_py_mask_methods) < 0) goto fail; /* hausdorff.masks' (_masks.c) */
    return m;
fail:
    Py_DECREF(m);
    return NULL;
}
