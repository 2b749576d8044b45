/*
 * npy.c -- NumPy .npy arrays of shape (N, 3), float32 or float64.
 *
 * Format (NumPy Enhancement Proposal 1, "A simple file format for NumPy
 * arrays", and numpy.lib.format): the magic "\x93NUMPY", a major and minor
 * version byte, the header length (u16 little-endian in version 1.0, u32
 * in 2.0 and 3.0), then the header: an ASCII (3.0: UTF-8) Python dict
 * literal with the keys 'descr', 'fortran_order' and 'shape', padded with
 * spaces and ended by '\n'.  The data follows: N * 3 elements in C order
 * (x, y, z of a point adjacent) or Fortran order (all x, then all y, then
 * all z).
 *
 * Read: descr '<f4', '>f4', '<f8', '>f8' (and '=' or '|' for the
 * machine's own order), fortran_order True or False, shape (N, 3).  The dict is
 * parsed key by key, so the keys may come in any order and with any
 * spacing, and anything else (object arrays, structured dtypes, other
 * shapes) is refused by name.  N * 3 * itemsize must fit in the file; the
 * points are converted in parallel from the mapping: C order is records of
 * 3 elements, Fortran order is x, y and z each in their own block, which
 * hd__binary_read expresses as offsets 0, N and 2N elements with a stride of
 * one element.
 */
#include "io.h"

#include <stdlib.h>

static const char *skip_ws(const char *p, const char *end) {
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')) p++;
    return p;
}

/* The value text after the first 'key' in the dict [p, end): *vb..*ve. */
static int first_key(const char *p, const char *end, const char *key, const char **vb, const char **ve) {
    size_t n = strlen(key);
    for (const char *q = p; q + n + 2 <= end; q++) {
        if ((*q != '\'' && *q != '"') || memcmp(q + 1, key, n) != 0 || q[n + 1] != *q) continue;
        const char *c = skip_ws(q + n + 2, end);
        if (c >= end || *c != ':') continue;
        c = skip_ws(c + 1, end);
        if (c == end) return 0;
        const char *e = c;
        if (e < end && *e == '(') {
            while (e < end && *e != ')') e++;
            if (e < end) e++;
        } else if (e < end && (*e == '\'' || *e == '"')) {
            char qch = *e++;
            while (e < end && *e != qch) e++;
            if (e < end) e++;
        } else {
            while (e < end && *e != ',' && *e != '}') e++;
        }
        *vb = c;
        *ve = e;
        return 1;
    }
    return 0;
}

/* The value text after 'key' in the dict [p, end): *vb..*ve and 1, 0 when
 * the key is missing, or -1 when it is given twice (Python keeps the last
 * value, so numpy reads a shape other than the first one given). */
static int find_key(const char *p, const char *end, const char *key, const char **vb, const char **ve) {
    const char *b2, *e2;
    if (!first_key(p, end, key, vb, ve)) return 0;
    return first_key(*ve, end, key, &b2, &e2) ? -1 : 1;
}

int hd__read_npy(hd__read_t *r) {
    const unsigned char *d = r->f->data;
    size_t size = r->f->size;
    if (size < 10 || memcmp(d, "\x93NUMPY", 6) != 0)
        return hd__io_err_at(r, HD_EFORMAT, 0, "not a NumPy .npy file (no \\x93NUMPY signature)");
    unsigned major = d[6];
    size_t hlen, hstart;
    if (major == 1) {
        hlen = hd__ld_u16(d + 8, 0);
        hstart = 10;
    } else if (major == 2 || major == 3) {
        if (size < 12) return hd__io_err_at(r, HD_EFORMAT, (long long)size, "file ends inside the .npy preamble");
        hlen = hd__ld_u32(d + 8, 0);
        hstart = 12;
    } else {
        return hd__io_err_at(r, HD_EUNSUPPORTED, 6, ".npy format version %u.%u (1.0 to 3.0 are read)", major, d[7]);
    }
    if (hlen > size - hstart)
        return hd__io_err_at(r, HD_EFORMAT, (long long)size, "file ends inside the .npy header (%zu bytes declared)", hlen);
    const char *h = (const char *)d + hstart, *he = h + hlen, *vb, *ve;
    size_t data = hstart + hlen;
    static const char *const keys[] = {"descr", "fortran_order", "shape"};
    for (int k = 0; k < 3; k++)
        if (find_key(h, he, keys[k], &vb, &ve) < 0)
            return hd__io_err_at(r, HD_EFORMAT, (long long)hstart, "the header gives '%s' twice", keys[k]);
    if (!find_key(h, he, "descr", &vb, &ve))
        return hd__io_err_at(r, HD_EFORMAT, (long long)hstart, "the header has no 'descr'");
    size_t dl = (size_t)(ve - vb);
    hd__type_t type = HD__T_NONE;
    int big = 0;
    if (dl == 5 && (vb[0] == '\'' || vb[0] == '"') && (vb[2] == 'f') && vb[4] == vb[0]) {
        char o = vb[1], s = vb[3];
        if (o == '<' || o == '=' || o == '|' || o == '>') {
            const uint16_t one = 1;
            unsigned char first;
            memcpy(&first, &one, 1);
            big = o == '>' || ((o == '=' || o == '|') && first == 0);
            type = s == '4' ? HD__T_F32 : s == '8' ? HD__T_F64 : HD__T_NONE;
        }
    }
    if (!type)
        return hd__io_err_at(r, HD_EUNSUPPORTED, (long long)(hstart + (size_t)(vb - h)),
                             "dtype %.*s (float32 or float64 arrays are read: '<f4', '>f4', '<f8', '>f8')",
                             (int)(dl > 40 ? 40 : dl), vb);
    if (!find_key(h, he, "fortran_order", &vb, &ve))
        return hd__io_err_at(r, HD_EFORMAT, (long long)hstart, "the header has no 'fortran_order'");
    int fortran;
    if (ve - vb == 4 && memcmp(vb, "True", 4) == 0) fortran = 1;
    else if (ve - vb == 5 && memcmp(vb, "False", 5) == 0) fortran = 0;
    else return hd__io_err_at(r, HD_EFORMAT, (long long)(hstart + (size_t)(vb - h)), "fortran_order is neither True nor False");
    if (!find_key(h, he, "shape", &vb, &ve) || *vb != '(')
        return hd__io_err_at(r, HD_EFORMAT, (long long)hstart, "the header has no 'shape' tuple");
    /* (N, 3) */
    uint64_t dims[3];
    int nd = 0;
    const char *q = vb + 1;
    for (;;) {
        q = skip_ws(q, ve);
        if (q < ve && *q == ')') break;
        const char *t = q;
        while (q < ve && *q >= '0' && *q <= '9') q++;
        if (nd == 3 || !hd__parse_u64(t, q, &dims[nd]))
            return hd__io_err_at(r, HD_EUNSUPPORTED, (long long)(hstart + (size_t)(vb - h)), "shape %.*s (an (N, 3) array is read)",
                                 (int)(ve - vb > 40 ? 40 : ve - vb), vb);
        nd++;
        q = skip_ws(q, ve);
        if (q < ve && *q == ',') q++;
    }
    if (nd != 2 || dims[1] != 3)
        return hd__io_err_at(r, HD_EUNSUPPORTED, (long long)(hstart + (size_t)(vb - h)), "shape %.*s (an (N, 3) array is read)",
                             (int)(ve - vb > 40 ? 40 : ve - vb), vb);
    uint64_t n = dims[0];
    size_t el = hd__type_size(type);
    if (n > (size - data) / (3 * el))
        return hd__io_err_at(r, HD_EFORMAT, (long long)size, "file ends inside the data: shape (%llu, 3) needs %llu bytes, %zu are left",
                             (unsigned long long)n, (unsigned long long)(n <= UINT64_MAX / (3 * el) ? n * 3 * el : UINT64_MAX),
                             size - data);
    if (n * 3 * el != size - data)
        return hd__io_err_at(r, HD_EFORMAT, (long long)(data + n * 3 * el),
                             "shape (%llu, 3) of %s needs %llu bytes of data, but %zu follow the header: "
                             "the shape or the dtype is wrong",
                             (unsigned long long)n, type == HD__T_F32 ? "float32" : "float64",
                             (unsigned long long)(n * 3 * el), size - data);
    hd__layout_t L = {(size_t)n, 1, 3 * el, 0, {0, el, 2 * el}, {type, type, type}, big, NULL, NULL, data};
    if (fortran) {
        L.stride = el;
        L.off[1] = (size_t)n * el;
        L.off[2] = 2 * (size_t)n * el;
    }
    return hd__binary_read(r, d + data, &L);
}
