/*
 * write_las.c -- fields written back into LAS (hd_write_fields), and the
 * LAS facts the LAZ writer shares with it.
 *
 * Format (ASPRS "LAS Specification 1.4 - R15", 2019): section 2.4 for the
 * header (las.c lists the fields read), 2.5 for the VLR header (u16
 * reserved, char[16] user id, u16 record id, u16 length after the header,
 * char[32] description: 54 bytes), 2.5.8 "Extra Bytes" (user "LASF_Spec",
 * record 4): one 192-byte descriptor per dimension, in the order of the
 * bytes after the point format's own fields: u8[2] reserved, u8 data type
 * (10 = double; 0 = undocumented bytes, as many as `options` says), u8
 * options (bit 1: min, bit 2: max valid), char[32] name, u8[4] unused,
 * anytype no_data, min, max (8 bytes each), f64[3] scale, f64[3] offset,
 * char[32] description.  Readers (PDAL, LAStools, QGIS through PDAL,
 * CloudCompare) take the VLR in any LAS version, so 1.0-1.3 files get it
 * too.
 *
 * What changes: the point data offset (the VLR's bytes), the VLR count
 * (a new VLR) or the existing extra-bytes VLR's length (a descriptor
 * appended), the record length (+8), the start of waveform data (1.3) and
 * of the extended VLRs (1.4) when they follow the points (moved by the
 * difference in the points' bytes); in a subset also the point counts (the
 * legacy ones 0 where 1.4 requires it: point formats 6-10), the counts by
 * return (from each kept record's return number) and the bounds (from the
 * kept records' coordinates, X * scale + offset as the reader computes
 * them).  Everything else is copied: other header bytes, every VLR, bytes
 * between the VLRs and the points, the records, whatever follows them.
 */
#include "io.h"
#include "lasfield.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>

static const unsigned char min_record[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

static void st_u16(unsigned char *p, unsigned v) {
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
}
static void st_u32(unsigned char *p, uint32_t v) {
    for (int i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}
void hd__st_u64(unsigned char *p, uint64_t v) {
    for (int i = 0; i < 8; i++) p[i] = (unsigned char)(v >> (8 * i));
}
static void st_f64(unsigned char *p, double v) {
    uint64_t u;
    memcpy(&u, &v, 8);
    hd__st_u64(p, u);
}
static double ld_f64(const unsigned char *p) {
    uint64_t u = hd__ld_u64(p, 0);
    double v;
    memcpy(&v, &u, 8);
    return v;
}

/* Bytes of an extra-bytes descriptor's dimension (data types 1-10 and
 * their deprecated 2- and 3-arrays 11-30; 0: `options` bytes), or 0 for a
 * type the specification does not define. */
static size_t eb_size(unsigned type, unsigned options) {
    static const unsigned char sz[11] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
    if (type == 0) return options;
    if (type <= 10) return sz[type];
    if (type <= 20) return 2 * (size_t)sz[type - 10];
    if (type <= 30) return 3 * (size_t)sz[type - 20];
    return 0;
}

static void descriptor(unsigned char *p, unsigned type, unsigned options, const char *name, double lo, double hi) {
    memset(p, 0, 192);
    p[2] = (unsigned char)type;
    p[3] = (unsigned char)options;
    memcpy(p + 4, name, strlen(name) < 32 ? strlen(name) : 32);
    if (type == 10) {
        st_f64(p + 64, lo);
        st_f64(p + 88, hi);
        snprintf((char *)p + 160, 32, "written by hausdorff %s", hd_version());
    } else {
        snprintf((char *)p + 160, 32, "bytes no descriptor named");
    }
}

int hd__las_plan(hd__writer_t *w, hd__las_plan_t *pl) {
    const unsigned char *d = w->in->data;
    memset(pl, 0, sizeof *pl);
    pl->minor = d[25];
    pl->header = hd__ld_u16(d + 94, 0);
    pl->offset = hd__ld_u32(d + 96, 0);
    pl->n_vlr = hd__ld_u32(d + 100, 0);
    pl->fmt = d[104] & 0x3f;
    pl->rec = hd__ld_u16(d + 105, 0);
    pl->count = hd__ld_u32(d + 107, 0);
    if (pl->minor >= 4 && pl->header >= 375) {
        uint64_t c64 = hd__ld_u64(d + 247, 0);
        if (c64 != 0 || pl->count == 0) pl->count = c64;
    }
    if (pl->fmt > 10 || pl->rec < min_record[pl->fmt])
        return hd__err(w->err, HD_EFORMAT, "%s: point format %u with records of %zu bytes", w->in->name, pl->fmt, pl->rec);
    pl->add = w->nf != 0;
    if (pl->add && pl->rec + 8 * w->nf > 65535)
        return hd__err(w->err, HD_EUNSUPPORTED, "%s: records of %zu bytes leave no room for %zu more (65535 at most)",
                       w->in->name, pl->rec, 8 * w->nf);
    /* the VLRs: where they end, and the extra-bytes VLR if any */
    size_t p = pl->header, described = 0;
    pl->eb_at = 0;
    for (uint32_t i = 0; i < pl->n_vlr; i++) {
        if (p + 54 > pl->offset || p + 54 + hd__ld_u16(d + p + 20, 0) > pl->offset)
            return hd__err(w->err, HD_EFORMAT, "%s: byte %zu: VLR %u of %u runs past the point data", w->in->name, p, i + 1,
                           pl->n_vlr);
        size_t len = hd__ld_u16(d + p + 20, 0);
        if (memcmp(d + p + 2, "copc\0", 5) == 0 && hd__ld_u16(d + p + 18, 0) == 1 && !pl->copc_at) {
            pl->copc_at = p;
            pl->copc_len = len;
        }
        if (memcmp(d + p + 2, "LASF_Spec\0", 10) == 0 && hd__ld_u16(d + p + 18, 0) == 4) {
            pl->eb_at = p;
            for (size_t q = p + 54; q + 192 <= p + 54 + len; q += 192) {
                described += eb_size(d[q + 2], d[q + 3]);
                long j = hd__w_field_named(w, (const char *)d + q + 4, 0);
                if (j >= 0)
                    return hd__err(w->err, HD_EINVAL, "%s: the extra-bytes VLR already describes a dimension '%s'; choose "
                                                      "another name",
                                   w->in->name, w->f[j].name);
            }
        }
        p += 54 + len;
    }
    pl->vlr_end = p;
    size_t extra = pl->rec - min_record[pl->fmt];
    if (pl->add && described > extra)
        return hd__err(w->err, HD_EFORMAT, "%s: the extra-bytes VLR describes %zu bytes, the records have %zu after point "
                                           "format %u's fields",
                       w->in->name, described, extra, pl->fmt);
    pl->end = pl->offset + (size_t)pl->count * pl->rec;
    pl->gap = pl->add ? extra - described : 0;
    pl->n_desc = pl->add ? w->nf + (pl->gap + 254) / 255 : 0; /* an undocumented descriptor holds 255 bytes at most */
    size_t old_len = pl->eb_at ? hd__ld_u16(d + pl->eb_at + 20, 0) : 0;
    if (pl->add && old_len + 192 * pl->n_desc > 65535)
        return hd__err(w->err, HD_EUNSUPPORTED, "%s: the extra-bytes VLR has no room for another descriptor", w->in->name);
    pl->vlr_added = pl->add ? 192 * pl->n_desc + (pl->eb_at ? 0 : 54) : 0;
    pl->out_rec = pl->rec + 8 * w->nf;
    return HD_OK;
}

/* The extra-bytes VLR's new part: the descriptors (an undocumented one per
 * 255 bytes not described, then the fields', each with the range of its
 * kept values), into buf (192 * n_desc). */
static void new_descriptors(const hd__writer_t *w, const hd__las_plan_t *pl, unsigned char *buf) {
    size_t gap = pl->gap, k = 0;
    for (; gap > 0; k++) {
        size_t g = gap > 255 ? 255 : gap;
        descriptor(buf + 192 * k, 0, (unsigned)g, "", 0, 0);
        gap -= g;
    }
    for (size_t j = 0; j < w->nf; j++, k++) {
        double lo, hi;
        hd__w_range(w, w->f[j].values, &lo, &hi);
        descriptor(buf + 192 * k, 10, 6, w->f[j].name, lo, hi);
    }
}

/* The header, VLRs and the bytes before the points, for `kept` points
 * whose values run from lo to hi; by_return[1..15] and bounds (max x, min
 * x, max y, min y, max z, min z) are used in a subset. */
void hd__las_write_head(hd__writer_t *w, const hd__las_plan_t *pl, uint64_t kept, const uint64_t by_return[16],
                        const double bounds[6], uint64_t points_bytes, const unsigned char *laz_vlr,
                        size_t laz_vlr_at, size_t laz_vlr_len) {
    const unsigned char *d = w->in->data;
    unsigned char *h = malloc(pl->header);
    if (!h) {
        w->werr = ENOMEM;
        return;
    }
    memcpy(h, d, pl->header);
    size_t new_offset = pl->offset + pl->vlr_added;
    st_u32(h + 96, (uint32_t)new_offset);
    st_u32(h + 100, pl->n_vlr + (pl->add && !pl->eb_at) - (pl->copc_drop && pl->copc_at));
    st_u16(h + 105, (unsigned)pl->out_rec);
    if (w->keep != HD_KEEP_ALL) {
        int legacy = pl->fmt < 6 && kept <= 0xFFFFFFFFu;
        st_u32(h + 107, legacy ? (uint32_t)kept : 0);
        for (int r = 1; r <= 5; r++) st_u32(h + 111 + 4 * (r - 1), legacy ? (uint32_t)by_return[r] : 0);
        for (int c = 0; c < 6; c++) st_f64(h + 179 + 8 * c, bounds[c]);
        if (pl->minor >= 4 && pl->header >= 375) {
            hd__st_u64(h + 247, kept);
            for (int r = 1; r <= 15; r++) hd__st_u64(h + 255 + 8 * (r - 1), by_return[r]);
        }
    }
    uint64_t old_end = pl->end, new_end = new_offset + points_bytes;
    if (pl->minor >= 3 && pl->header >= 235) {
        uint64_t wave = hd__ld_u64(d + 227, 0);
        if (wave >= old_end && wave != 0) hd__st_u64(h + 227, wave - old_end + new_end);
    }
    if (pl->minor >= 4 && pl->header >= 247 && hd__ld_u32(d + 243, 0) > 0) {
        uint64_t evlr = hd__ld_u64(d + 235, 0);
        if (evlr >= old_end) hd__st_u64(h + 235, evlr - old_end + new_end);
        if (pl->copc_drop && pl->hier_at) { /* the hierarchy EVLR dropped: the next takes its place */
            uint32_t left = hd__ld_u32(d + 243, 0) - 1;
            st_u32(h + 243, left);
            if (left == 0) hd__st_u64(h + 235, 0);
        }
    }
    hd__w_put(w, h, pl->header);
    free(h);
    /* the VLRs: the extra-bytes one grown, or a new one after the last */
    unsigned char desc[54];
    unsigned char *nd = malloc(192 * pl->n_desc + 1);
    if (!nd) {
        w->werr = ENOMEM;
        return;
    }
    if (pl->add) new_descriptors(w, pl, nd);
    size_t p = pl->header;
    for (uint32_t i = 0; i < pl->n_vlr; i++) {
        size_t len = hd__ld_u16(d + p + 20, 0);
        if (pl->copc_at && p == pl->copc_at && (pl->copc_drop || pl->copc_info)) { /* COPC's info VLR */
            if (!pl->copc_drop) {
                hd__w_put(w, d + p, 54);
                hd__w_put(w, pl->copc_info, len);
            }
        } else if (laz_vlr && p + 54 == laz_vlr_at) { /* the LASzip VLR, rewritten by the LAZ writer */
            memcpy(desc, d + p, 54);
            st_u16(desc + 20, (unsigned)laz_vlr_len);
            hd__w_put(w, desc, 54);
            hd__w_put(w, laz_vlr, laz_vlr_len);
        } else if (pl->add && p == pl->eb_at) {
            memcpy(desc, d + p, 54);
            st_u16(desc + 20, (unsigned)(len + 192 * pl->n_desc));
            hd__w_put(w, desc, 54);
            hd__w_put(w, d + p + 54, len);
            hd__w_put(w, nd, 192 * pl->n_desc);
        } else {
            hd__w_put(w, d + p, 54 + len);
        }
        p += 54 + len;
    }
    if (pl->add && !pl->eb_at) {
        memset(desc, 0, 54);
        memcpy(desc + 2, "LASF_Spec", 9);
        st_u16(desc + 18, 4);
        st_u16(desc + 20, (unsigned)(192 * pl->n_desc));
        snprintf((char *)desc + 22, 32, "Extra Bytes");
        hd__w_put(w, desc, 54);
        hd__w_put(w, nd, 192 * pl->n_desc);
    }
    free(nd);
    hd__w_put(w, d + pl->vlr_end, pl->offset - pl->vlr_end);
}

uint64_t hd__las_put_tail(hd__writer_t *w, const hd__las_plan_t *pl, size_t from) {
    const unsigned char *d = w->in->data;
    size_t end = w->in->size;
    if (!pl->hier_at || pl->hier_at < from || (!pl->copc_drop && !pl->copc_hier)) {
        hd__w_put(w, d + from, end - from);
        return end - from;
    }
    size_t at = (size_t)pl->hier_at, data_end = at + 60 + (size_t)pl->hier_len;
    hd__w_put(w, d + from, at - from);
    if (!pl->copc_drop) {
        hd__w_put(w, d + at, 60);
        hd__w_put(w, pl->copc_hier, (size_t)pl->hier_len);
    }
    hd__w_put(w, d + data_end, end - data_end);
    return pl->copc_drop ? end - from - (data_end - at) : end - from;
}

/* The return number of a record (formats 0-5: bits 0-2 of byte 14;
 * 6-10: bits 0-3). */
unsigned hd__las_return(const unsigned char *r, unsigned fmt) { return fmt >= 6 ? r[14] & 15 : r[14] & 7; }

void hd__las_bound(double bounds[6], const unsigned char *r, const double scale[3], const double shift[3], int first) {
    for (int c = 0; c < 3; c++) {
        double x = (double)(int32_t)hd__ld_u32(r + 4 * c, 0) * scale[c] + shift[c];
        if (first || x > bounds[2 * c]) bounds[2 * c] = x;
        if (first || x < bounds[2 * c + 1]) bounds[2 * c + 1] = x;
    }
}

void hd__las_scale(const unsigned char *d, double scale[3], double shift[3]) {
    for (int c = 0; c < 3; c++) {
        scale[c] = ld_f64(d + 131 + 8 * c);
        shift[c] = ld_f64(d + 155 + 8 * c);
    }
}

/* The range of the kept points' values v (0, 0 when none is finite). */
void hd__w_range(const hd__writer_t *w, const double *v, double *lo, double *hi) {
    int any = 0;
    *lo = *hi = 0;
    for (size_t k = 0; k < w->n; k++)
        if (hd__w_keep(w, k) && isfinite(v[k])) {
            if (!any || v[k] < *lo) *lo = v[k];
            if (!any || v[k] > *hi) *hi = v[k];
            any = 1;
        }
}

/* The header las.c builds, from a header it has accepted. */
void hd__las_header_of(const hd__writer_t *w, const hd__las_plan_t *pl, hd__las_header_t *h) {
    const unsigned char *d = w->in->data;
    memset(h, 0, sizeof *h);
    h->minor = pl->minor;
    h->fmt = pl->fmt;
    h->header = pl->header;
    h->offset = pl->offset;
    h->rec = pl->rec;
    h->count = pl->count;
    h->n_vlr = pl->n_vlr;
    h->evlr = pl->minor >= 4 && pl->header >= 247 && hd__ld_u32(d + 243, 0) > 0 ? hd__ld_u64(d + 235, 0) : 0;
    hd__las_scale(d, h->scale, h->shift);
}

int hd__write_las(hd__writer_t *w) {
    hd__las_plan_t pl;
    int rc = hd__las_plan(w, &pl);
    if (rc) return rc;
    if (pl.count != w->n)
        return hd__err(w->err, HD_EINVAL, "%s: %zu values for %llu points", w->in->name, w->n, (unsigned long long)pl.count);
    if (pl.end > w->in->size) return hd__err(w->err, HD_EFORMAT, "%s: the points run past the file's end", w->in->name);
    const unsigned char *d = w->in->data;
    uint64_t by_return[16] = {0}, kept = 0;
    double bounds[6] = {0}, scale[3], shift[3];
    hd__las_scale(d, scale, shift);
    for (size_t k = 0; k < w->n; k++)
        if (hd__w_keep(w, k)) {
            const unsigned char *r = d + pl.offset + k * pl.rec;
            by_return[hd__las_return(r, pl.fmt)]++;
            hd__las_bound(bounds, r, scale, shift, kept++ == 0);
        }
    hd__las_write_head(w, &pl, kept, by_return, bounds, kept * pl.out_rec, NULL, 0, 0);
    /* the records, staged a block at a time */
    enum { BLOCK = 1 << 16 };
    unsigned char *buf = malloc(BLOCK + pl.out_rec);
    if (!buf) return hd__err(w->err, HD_ENOMEM, "out of memory");
    size_t used = 0;
    for (size_t k = 0; k < w->n && !w->werr; k++) {
        if (!hd__w_keep(w, k)) continue;
        memcpy(buf + used, d + pl.offset + k * pl.rec, pl.rec);
        used += pl.rec;
        hd__w_values(w, k, 0, buf + used);
        used += 8 * w->nf;
        if (used >= BLOCK) {
            hd__w_put(w, buf, used);
            used = 0;
        }
        w->written++;
    }
    hd__w_put(w, buf, used);
    free(buf);
    hd__las_put_tail(w, &pl, pl.end); /* waveform data, extended VLRs */
    return HD_OK;
}
