/*
 * _masks.c -- the C side of hausdorff.masks (masks.py): a mask's surface
 * points (hd_mask_points, the command line's NIfTI masks' function) and the
 * figures of per-point distances (hd_summarize, hd_percentile_of,
 * hd_tolerance_scores, hd_capped_means), so that Python's numbers are the
 * command line's to the bit.
 *
 * Arrays come through the buffer protocol, already in the layout the
 * library reads (masks.py converts them: a mask to uint8 in Fortran order,
 * i.e. axis 0 fastest; distances to contiguous float64), and results go
 * back as bytes or tuples for masks.py to wrap.  The library's work runs
 * without the GIL.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hausdorff.h"
#include "_masks.h"

static PyObject *raise_hd(int rc, const hd_error_t *err) {
    PyErr_SetString(rc == HD_ENOMEM ? PyExc_MemoryError : PyExc_ValueError, err->message);
    return NULL;
}

/* The mask over the buffer `vox` of shape n and spacing sp, or -1 with
 * ValueError (and the buffer released) when its length is not the shape's. */
static int mask_view(Py_buffer *vox, const Py_ssize_t n[3], const double sp[3], hd_mask_t *mk) {
    if (n[0] < 1 || n[1] < 1 || n[2] < 1 || vox->len != n[0] * n[1] * n[2]) {
        PyBuffer_Release(vox);
        PyErr_SetString(PyExc_ValueError, "the mask's buffer does not hold its shape");
        return -1;
    }
    hd_mask_init(mk, vox->buf, (size_t)n[0], (size_t)n[1], (size_t)n[2], sp);
    return 0;
}

/* _mask_points(voxels, n0, n1, n2, s0, s1, s2, connectivity, dims, all)
 * -> (bytes of n * 3 float64, foreground, surface_dims, connectivity) */
static PyObject *py_mask_points(PyObject *self, PyObject *args) {
    (void)self;
    Py_buffer vox;
    Py_ssize_t n[3];
    double sp[3];
    int connectivity, dims, all;
    if (!PyArg_ParseTuple(args, "y*nnndddiip", &vox, &n[0], &n[1], &n[2], &sp[0], &sp[1], &sp[2],
                          &connectivity, &dims, &all))
        return NULL;
    hd_mask_t mk;
    if (mask_view(&vox, n, sp, &mk) < 0) return NULL;
    hd_mask_options_t mo;
    hd_mask_options_init(&mo);
    mo.points = all ? HD_MASK_ALL : HD_MASK_SURFACE;
    mo.connectivity = connectivity;
    mo.dims = dims;
    hd_cloud_t *c = NULL;
    hd_mask_info_t info;
    hd_error_t err;
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = hd_mask_points(&mk, &mo, &c, &info, &err);
    Py_END_ALLOW_THREADS
    PyBuffer_Release(&vox);
    if (rc != HD_OK) return raise_hd(rc, &err);
    PyObject *bytes = PyBytes_FromStringAndSize(c->data, (Py_ssize_t)(c->count * 3 * sizeof(double)));
    hd_cloud_free(c);
    if (!bytes) return NULL;
    return Py_BuildValue("Nnii", bytes, (Py_ssize_t)info.foreground, info.surface_dims, info.connectivity);
}

/* A float64 buffer, or None (NULL, 0 values). */
static int get_doubles(PyObject *o, Py_buffer *b, const double **p, size_t *n) {
    memset(b, 0, sizeof *b);
    *p = NULL;
    *n = 0;
    if (o == Py_None) return 0;
    if (PyObject_GetBuffer(o, b, PyBUF_C_CONTIGUOUS) < 0) return -1;
    *p = b->buf;
    *n = (size_t)b->len / sizeof(double);
    return 0;
}

static void release(Py_buffer *b) {
    if (b->obj) PyBuffer_Release(b);
}

/* _figures(d_ab, d_ba, w_a, w_b, percentiles, taus, strict, cap)
 * -> (summary tuple, [percentile tuples], [tolerance tuples], capped tuple
 *    or None); d_ba None: directed.  With no d_ab the summary is NaN and no
 *    percentile is computed (the caller asks for tolerances only). */
static PyObject *py_figures(PyObject *self, PyObject *args) {
    (void)self;
    PyObject *o[6];
    int strict;
    double cap;
    if (!PyArg_ParseTuple(args, "OOOOOOpd", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5], &strict, &cap)) return NULL;
    Py_buffer b[6];
    const double *p[6];
    size_t n[6];
    int got = 0;
    for (; got < 6; got++)
        if (get_doubles(o[got], &b[got], &p[got], &n[got]) < 0) break;
    PyObject *res = NULL;
    if (got < 6) goto done;
    hd_summary_t s;
    hd_percentile_t *pct = PyMem_Calloc(n[4] ? n[4] : 1, sizeof *pct);
    hd_tolerance_t *tol = PyMem_Calloc(n[5] ? n[5] : 1, sizeof *tol);
    hd_capped_mean_t cm;
    hd_error_t err;
    int rc = HD_OK;
    if (!pct || !tol) {
        PyErr_NoMemory();
        goto out;
    }
    Py_BEGIN_ALLOW_THREADS
    if (n[0]) rc = hd_summarize(p[0], n[0], p[1], n[1], &s, &err);
    else s.max_ab = s.max_ba = s.mean_ab = s.mean_ba = s.mean_symmetric = s.mean_average = s.mean_pooled =
        s.chamfer = s.chamfer_sum2 = NAN; /* an empty side: only the tolerances are asked */
    for (size_t k = 0; rc == HD_OK && n[0] && k < n[4]; k++) rc = hd_percentile_of(p[0], n[0], p[1], n[1], p[4][k], &pct[k], &err);
    if (rc == HD_OK)
        rc = hd_tolerance_scores(p[0], p[2], n[0], p[1], p[3], n[1], p[5], n[5], strict ? HD_BELOW : HD_AT_MOST, tol, &err);
    if (rc == HD_OK && cap > 0) rc = hd_capped_means(p[0], n[0], p[1], n[1], cap, &cm, &err);
    Py_END_ALLOW_THREADS
    if (rc != HD_OK) {
        raise_hd(rc, &err);
        goto out;
    }
    PyObject *lp = PyList_New((Py_ssize_t)n[4]), *lt = PyList_New((Py_ssize_t)n[5]);
    for (size_t k = 0; lp && k < n[4]; k++)
        PyList_SET_ITEM(lp, (Py_ssize_t)k, Py_BuildValue("ddddd", pct[k].p, pct[k].ab, pct[k].ba, pct[k].symmetric,
                                                         pct[k].pooled));
    for (size_t k = 0; lt && k < n[5]; k++)
        PyList_SET_ITEM(lt, (Py_ssize_t)k, Py_BuildValue("dddddnn", tol[k].tau, tol[k].precision, tol[k].recall,
                                                         tol[k].fscore, tol[k].nsd, (Py_ssize_t)tol[k].count_ab,
                                                         (Py_ssize_t)tol[k].count_ba));
    PyObject *cs = cap > 0 ? Py_BuildValue("dddnn", cm.accuracy, cm.completeness, cm.overall, (Py_ssize_t)cm.kept_ab,
                                           (Py_ssize_t)cm.kept_ba)
                           : (Py_INCREF(Py_None), Py_None);
    PyObject *ss = Py_BuildValue("ddddddddd", s.max_ab, s.max_ba, s.mean_ab, s.mean_ba, s.mean_symmetric,
                                 s.mean_average, s.mean_pooled, s.chamfer, s.chamfer_sum2);
    if (lp && lt && cs && ss) res = Py_BuildValue("NNNN", ss, lp, lt, cs);
    else {
        Py_XDECREF(lp), Py_XDECREF(lt), Py_XDECREF(cs), Py_XDECREF(ss);
    }
out:
    PyMem_Free(pct);
    PyMem_Free(tol);
done:
    for (int k = 0; k < got; k++) release(&b[k]);
    return res;
}


/* The row of a label map as a tuple, in the order masks.py's _ROW names. */
static PyObject *row_tuple(const hd_label_row_t *r) {
    return Py_BuildValue("Linnnd" "nnddddddddd" "nndddddddd" "nn", (long long)r->label, r->empty,
                         (Py_ssize_t)r->voxels_a, (Py_ssize_t)r->voxels_b, (Py_ssize_t)r->overlap, r->dice,
                         (Py_ssize_t)r->points_a, (Py_ssize_t)r->points_b, r->hausdorff, r->hd_ab, r->hd_ba, r->hd_p,
                         r->hd_p_pooled, r->assd, r->asd_ab, r->asd_ba, r->nsd, (Py_ssize_t)r->surfels_a,
                         (Py_ssize_t)r->surfels_b, r->area_a, r->area_b, r->nsd_surfel, r->overlap_ab, r->overlap_ba,
                         r->hd_surfel, r->asd_surfel_ab, r->asd_surfel_ba, (Py_ssize_t)r->components_a,
                         (Py_ssize_t)r->components_b);
}

static PyObject *component_tuple(const hd_label_component_t *c) {
    return Py_BuildValue("Linnnndddi", (long long)c->label, c->side, (Py_ssize_t)c->index, (Py_ssize_t)c->voxels,
                         (Py_ssize_t)c->overlap, (Py_ssize_t)c->points, c->hausdorff, c->hd_p, c->nearest,
                         c->detected);
}

static PyObject *table_lists(const hd_label_table_t *t) {
    PyObject *rows = PyList_New((Py_ssize_t)t->n_rows), *comps = PyList_New((Py_ssize_t)t->n_components);
    int ok = rows && comps;
    for (size_t k = 0; ok && k < t->n_rows; k++) {
        PyObject *o = row_tuple(&t->rows[k]);
        if (!o) ok = 0;
        else PyList_SET_ITEM(rows, (Py_ssize_t)k, o);
    }
    for (size_t k = 0; ok && k < t->n_components; k++) {
        PyObject *o = component_tuple(&t->components[k]);
        if (!o) ok = 0;
        else PyList_SET_ITEM(comps, (Py_ssize_t)k, o);
    }
    if (ok) return Py_BuildValue("NN", rows, comps);
    Py_XDECREF(rows), Py_XDECREF(comps);
    return NULL;
}

/* An image of ndim axes, its spacing s given by the array's axes: stored
 * axis 0 fastest (corder 0: library axis c is array axis c), or the last
 * axis fastest (corder 1: library axis ndim-1-c is array axis c).  Either
 * way array axis c goes to world axis c at s[c] per voxel, and, the map
 * having one nonzero per row, each coordinate is s[c] times the index,
 * exactly, as hd_mask_init's diagonal gives it. */
static void place(hd_label_image_t *im, const double s[3], int ndim, int corder) {
    memset(im->m, 0, sizeof im->m);
    for (int c = 0; c < 3; c++) im->m[c][corder && c < ndim ? ndim - 1 - c : c] = s[c];
}

/* _label_map(a, b, type, n0, n1, n2, (sa0, sa1, sa2), (sb0, sb1, sb2),
 *            labels bytes of int64 or None, percentile, tau, strict,
 *            connectivity, dims, empty name, components, threads, ndim,
 *            corder)
 * -> ([row tuples], [component tuples]); n0 is the fastest axis. */
static PyObject *py_label_map(PyObject *self, PyObject *args) {
    (void)self;
    Py_buffer va, vb;
    PyObject *lab;
    Py_ssize_t n[3];
    double sa[3], sb[3], pct, tau;
    int type, strict, conn, dims, comps, threads, ndim, corder;
    const char *empty;
    if (!PyArg_ParseTuple(args, "y*y*innn(ddd)(ddd)Oddpiisiiip", &va, &vb, &type, &n[0], &n[1], &n[2], &sa[0], &sa[1],
                          &sa[2], &sb[0], &sb[1], &sb[2], &lab, &pct, &tau, &strict, &conn, &dims, &empty, &comps,
                          &threads, &ndim, &corder))
        return NULL;
    PyObject *res = NULL;
    Py_buffer lb;
    memset(&lb, 0, sizeof lb);
    hd_label_options_t o;
    hd_label_options_init(&o);
    hd_error_t err;
    if (hd_empty_policy_from_name(empty, &o.empty) != HD_OK) {
        PyErr_Format(PyExc_ValueError, "unknown empty policy %s", empty);
        goto done;
    }
    if (lab != Py_None) {
        if (PyObject_GetBuffer(lab, &lb, PyBUF_C_CONTIGUOUS) < 0) goto done;
        o.labels = lb.buf;
        o.n_labels = (size_t)lb.len / sizeof(int64_t);
    }
    o.percentile = pct, o.tau = tau, o.rule = strict ? HD_BELOW : HD_AT_MOST;
    o.connectivity = conn, o.dims = dims, o.components = comps, o.threads = threads;
    static const int size[] = {1, 1, 2, 2, 4, 4, 8, 8};
    if (type < 0 || type > 7 || n[0] < 1 || n[1] < 1 || n[2] < 1 || va.len != n[0] * n[1] * n[2] * size[type] ||
        vb.len != va.len) {
        PyErr_SetString(PyExc_ValueError, "the label images' buffers do not hold their shape");
        goto done;
    }
    hd_label_image_t ia, ib;
    hd_label_image_init(&ia, va.buf, (hd_label_type_t)type, (size_t)n[0], (size_t)n[1], (size_t)n[2], sa);
    hd_label_image_init(&ib, vb.buf, (hd_label_type_t)type, (size_t)n[0], (size_t)n[1], (size_t)n[2], sb);
    place(&ia, sa, ndim, corder);
    place(&ib, sb, ndim, corder);
    hd_label_table_t *t = NULL;
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = hd_label_map(&ia, &ib, &o, &t, &err);
    Py_END_ALLOW_THREADS
    if (rc != HD_OK) raise_hd(rc, &err);
    else res = table_lists(t);
    hd_label_table_free(t);
done:
    if (lb.obj) PyBuffer_Release(&lb);
    PyBuffer_Release(&va);
    PyBuffer_Release(&vb);
    return res;
}


/* _mask_surfels(voxels, n0, n1, n2, s0, s1, s2, dims)
 * -> (bytes of n * 3 float64 centres, bytes of n float64 areas) */
static PyObject *py_mask_surfels(PyObject *self, PyObject *args) {
    (void)self;
    Py_buffer vox;
    Py_ssize_t n[3];
    double sp[3];
    int dims;
    if (!PyArg_ParseTuple(args, "y*nnndddi", &vox, &n[0], &n[1], &n[2], &sp[0], &sp[1], &sp[2], &dims)) return NULL;
    hd_mask_t mk;
    if (mask_view(&vox, n, sp, &mk) < 0) return NULL;
    hd_cloud_t *c = NULL;
    double *areas = NULL;
    hd_error_t err;
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = hd_mask_surfels(&mk, dims, &c, &areas, &err);
    Py_END_ALLOW_THREADS
    PyBuffer_Release(&vox);
    if (rc != HD_OK) return raise_hd(rc, &err);
    PyObject *res = Py_BuildValue("y#y#", (const char *)c->data, (Py_ssize_t)(c->count * 3 * sizeof(double)),
                                  (const char *)areas, (Py_ssize_t)(c->count * sizeof(double)));
    hd_cloud_free(c);
    free(areas);
    return res;
}

PyMethodDef hd_py_mask_methods[] = {
    {"_mask_points", py_mask_points, METH_VARARGS, "A mask's surface points (hausdorff.masks)."},
    {"_mask_surfels", py_mask_surfels, METH_VARARGS, "A mask's surfels (hausdorff.masks.surfels)."},
    {"_label_map", py_label_map, METH_VARARGS, "Every label's figures (hausdorff.masks.label_map)."},
    {"_figures", py_figures, METH_VARARGS, "Figures of per-point distances (hausdorff.masks)."},
    {NULL, NULL, 0, NULL},
};
