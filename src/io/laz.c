/*
 * laz.c -- LAZ: LAS whose point records are compressed by LASzip, read to
 * x, y, z (written from the format's public description: the LASzip
 * sources and the LAZ specification; facts, not code).
 *
 * Layout.  The LAS header (las.c has checked it) has bit 7 of the point
 * format byte set; a VLR of user "laszip encoded", record 22204, says how:
 * u16 compressor (2 pointwise chunked, 3 layered chunked), u16 coder (0
 * arithmetic), u8 u8 u16 version, u32 options, u32 chunk size (0 or
 * 2^32-1: variable), i64 i64 (special EVLRs), u16 item count and per item
 * u16 type, u16 size, u16 version.  At the point offset an i64 gives the
 * chunk table's place (0 or -1: in the last 8 bytes of the file); the
 * chunks follow those 8 bytes back to back.  The table is u32 version 0,
 * u32 chunk count, then per chunk (variable chunk sizes: its point count,
 * integer-compressor context 0) its byte size (context 1), each predicted
 * from the previous chunk's value, in one range-coded stream (IC of 32
 * bits, 2 contexts).
 *
 * A chunk starts with its first point as a raw record.  Pointwise
 * (formats 0-5: POINT10 v2, GPSTIME11 v2, RGB12 v2, BYTE v2 items): one
 * range-coded stream after it holds every field of every following point
 * in item order, so every item is decoded to stay in step, though only
 * x, y, z are kept.  Layered (formats 6-10: POINT14 v3/v4 and RGB14,
 * RGBNIR14, WAVEPACKET14, BYTE14 items): u32 point count, a u32 byte size
 * per layer (9 for POINT14, 1 RGB14, 2 RGBNIR14, 1 WAVEPACKET14, one per
 * extra byte), then the layers, each its own stream; x and y are in the
 * first layer (with the return counts and scanner channel that choose
 * their contexts), z in the second, and every other layer is skipped by
 * its size (the writers of subsets decode every layer of a chunk through
 * hd__laz_chunk_records, in laz14.c; a read never does).  COPC files are
 * layered LAZ with variable chunk sizes.
 *
 * POINT10 v2, per point: a symbol of 64 says which of the return byte,
 * intensity, classification, scan angle, user data, point source changed;
 * the changed ones follow; then dx = IC(median of the last five dx of the
 * same return context m, context n==1), dy likewise (context from dx's k),
 * z = IC(last z of return level l, context from the mean k of dx, dy).
 * POINT14 v3: the same in spirit, per scanner channel (up to 4 sets of
 * models, created when the channel first appears, from the previous
 * channel's last point), with the return context also split by whether the
 * GPS time changed.
 *
 * Invariants and checks (bad input is an error with a byte offset, never
 * a crash, hang or allocation beyond what the file can hold): the VLRs lie
 * inside the header's VLR area; the items cover the record length exactly
 * and are the ones listed above; the chunk table lies after the chunk data
 * start, its chunk count is at most the bytes before it (each chunk is at
 * least one byte), every chunk has bytes and ends before the table, the
 * points per chunk add up to the header's count, and no chunk claims more
 * points per byte of it than the read options' laz_points_per_byte
 * (default HD_LAZ_POINTS_PER_BYTE, which degenerate data in LASzip's
 * chunks stays below; never above HD_LAZ_POINTS_PER_BYTE_MAX: a point
 * costs at least a few thousandths of a bit in the format's most skewed
 * models; see docs/formats.md), so that a file's result is bounded by its
 * size, and above
 * HD__LAZ_EAGER_PER_BYTE points per byte the result is not allocated up
 * front but grown while the chunks are decoded in order, so that only
 * decoded points cost memory; a chunk's
 * layer sizes fill it exactly; every decoded stream (a pointwise chunk's,
 * a layered chunk's x/y and z layers when they have bytes) ends exactly
 * where its decoder stops after the chunk's last point: LASzip's encoder
 * ends a stream with the bytes its decoder reads ahead, so reading past
 * them means fewer points than counted, and bytes left mean more (or items
 * other than the VLR's).  A one-point chunk's stream is the four bytes of
 * an empty one.  The last chunk is decoded by every read, range reads and
 * hd_read_count included, since a header count lower than the data shows
 * only there.  Chunks are decoded in parallel, each by
 * itself with models of its own, straight into its window of the sink;
 * the first failing chunk in file order is the error, so the message does
 * not depend on the thread count.  Coordinates are X * scale + offset in
 * double, as for LAS.
 */
#include "io.h"
#include "laz14.h"
#include "lazcoder.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>


enum { IT_BYTE = 0, IT_POINT10 = 6, IT_GPSTIME11 = 7, IT_RGB12 = 8, IT_WAVE13 = 9, IT_POINT14 = 10, IT_RGB14 = 11,
       IT_RGBNIR14 = 12, IT_WAVE14 = 13, IT_BYTE14 = 14 };

typedef struct {
    unsigned type, size, version;
} item_t;

typedef struct {
    hd__read_t *r;
    const unsigned char *d;
    size_t size;
    int layered, chunked;
    int grow; /* decode sequentially, growing the result (see hd__read_laz) */
    size_t rec;
    item_t items[32];
    unsigned n_items, n_layers;
    size_t n_chunks;
    uint64_t *start; /* n_chunks + 1 byte offsets */
    uint64_t *first; /* n_chunks + 1 cumulative point counts */
    unsigned per_byte; /* the most points a chunk may hold per byte of it */
    size_t start_table, table_end; /* the chunk table's first byte and its end */
    uint64_t lo, hi; /* the points kept: [lo, hi) of the file's (a range
                        read keeps part; chunks outside it are not decoded) */
    double scale[3], shift[3];
    /* per chunk: the first problem */
    int *rc;
    long long *at;
    char (*msg)[320];
} laz_t;

/* ---- one chunk's work ------------------------------------------------------ */
typedef struct {
    laz_t *z;
    size_t chunk;
    hd__sink_t *s;
    double lim;
    size_t k; /* next point index in the sink */
    int rc;
    long long at;
    char msg[320];
    unsigned char *chan; /* NULL, or the scanner channel of each point of a
                            layered chunk (hd__laz_chunk_channels) */
    unsigned char *recs; /* NULL, or every whole record of a pointwise chunk
                            (hd__laz_chunk_records) */
} job_t;

static int fail(job_t *j, int code, long long at, const char *fmt, ...) HD__PRINTF(4, 5);
static int fail(job_t *j, int code, long long at, const char *fmt, ...) {
    if (j->rc) return j->rc;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(j->msg, sizeof j->msg, fmt, ap);
    va_end(ap);
    j->rc = code;
    j->at = at;
    return code;
}

/* Store point k from integer coordinates; 0 or the point's problem. */
static int put(job_t *j, int32_t X, int32_t Y, int32_t Z) {
    const laz_t *z = j->z;
    if (j->k < z->lo || j->k >= z->hi) { /* outside a range read: decoded, not kept */
        j->k++;
        return 0;
    }
    double p[3] = {(double)X * z->scale[0] + z->shift[0], (double)Y * z->scale[1] + z->shift[1],
                   (double)Z * z->scale[2] + z->shift[2]};
    if (!(fabs(p[0]) <= j->lim && fabs(p[1]) <= j->lim && fabs(p[2]) <= j->lim)) {
        int code = hd__point_valid(p, j->s->dtype), c = 0;
        while (c < 2 && hd__point_valid((double[3]){p[c], 0, 0}, j->s->dtype) == HD_OK) c++;
        return fail(j, code, (long long)z->start[j->chunk], "point %zu (in the chunk starting here): %s (%c = %g)", j->k,
                    hd__point_problem(code), "xyz"[c], p[c]);
    }
    size_t at = j->k - (size_t)z->lo;
    if (at >= j->s->cap) { /* the sequential path grows the result as points appear */
        assert(j->z->grow);
        j->s->count = at;
        int rc = hd__sink_reserve(j->s, 1 << 16);
        if (rc) return fail(j, rc, (long long)z->start[j->chunk], "cannot allocate %zu points: %s", at + 1, hd_strerror(rc));
    }
    hd__sink_set(j->s, at, p);
    j->k++;
    return 0;
}

static int32_t i32_at(const unsigned char *p) { return (int32_t)hd__ld_u32(p, 0); }

/* ---- POINT10 and the pointwise items, versions 1 and 2 --------------------- */
/* Every model of a pointwise chunk, zeroed first so that freeing is always
 * safe; each item uses the fields of its version. */
typedef struct {
    hd__pw_models_t m; /* POINT10, GPSTIME11, RGB12 (lazcoder.h) */
    /* POINT10 */
    int32_t diff1[2][3]; /* v1: the last three dx, dy */
    unsigned incr1;
    uint16_t last_int[16];
    int32_t last_h[8];
    unsigned char last[20];
    /* GPSTIME11 */
    int64_t t[4];
    int32_t gdiff[4];
    int extreme[4];
    unsigned glast, gnext;
    /* BYTE */
    unsigned nb;
    hd__symmodel_t **bm; /* v2: nb models, each created at its first symbol
                            (see bytes_read) */
    hd__intcoder_t bic;  /* v1: nb contexts */
    /* the values of RGB12 v2 and BYTE v2, followed only when whole records
     * are asked for (job_t's recs: hd__laz_chunk_records) */
    int values;
    uint16_t rgb[3];
    unsigned char *blast; /* nb bytes */
} pw_t;

static void pw_free(pw_t *w) {
    hd__pw_models_free(&w->m);
    hd__intcoder_free(&w->bic);
    if (w->bm)
        for (unsigned i = 0; i < w->nb; i++)
            if (w->bm[i]) {
                hd__symmodel_free(w->bm[i]);
                free(w->bm[i]);
            }
    free(w->bm);
    free(w->blast);
}

/* Create the models of every item, in the version the VLR gives it. */
static int pw_new(pw_t *w, const laz_t *z) {
    memset(w, 0, sizeof *w);
    int rc = hd__pw_point10_new(&w->m, z->items[0].version == 2);
    for (unsigned i = 1; i < z->n_items && rc == HD_OK; i++) {
        unsigned t = z->items[i].type, iv2 = z->items[i].version == 2;
        if (t == IT_GPSTIME11) {
            rc = hd__pw_gps11_new(&w->m, iv2);
        } else if (t == IT_RGB12) {
            rc = hd__pw_rgb12_new(&w->m, iv2);
        } else if (t == IT_BYTE) {
            w->nb = z->items[i].size;
            if (!iv2) {
                rc = hd__intcoder_new(&w->bic, 8, w->nb);
                continue;
            }
            w->bm = calloc(w->nb, sizeof *w->bm);
            if (!w->bm) return HD_ENOMEM;
        }
    }
    return rc;
}

/* The model at *slot, created on first use (LASzip creates these lazily
 * and initialises them when created). */
static hd__symmodel_t *lazy(hd__symmodel_t **slot, uint32_t n) {
    if (!*slot) {
        hd__symmodel_t *m = malloc(sizeof *m);
        if (!m) return NULL;
        if (hd__symmodel_new(m, n)) {
            free(m);
            return NULL;
        }
        *slot = m;
    }
    return *slot;
}

/* A byte from the model chosen by the byte's last value: 0, or -1 when
 * the model could not be allocated. */
static int lazy_byte(hd__symmodel_t **models, unsigned char *byte, hd__dec_t *d) {
    hd__symmodel_t *m = lazy(&models[*byte], 256);
    if (!m) return -1;
    *byte = (unsigned char)hd__dec_symbol(d, m);
    return 0;
}

static void set_xyz(unsigned char *L, int32_t X, int32_t Y, int32_t Z) {
    for (int b = 0; b < 4; b++) {
        L[b] = (unsigned char)((uint32_t)X >> (8 * b));
        L[4 + b] = (unsigned char)((uint32_t)Y >> (8 * b));
        L[8 + b] = (unsigned char)((uint32_t)Z >> (8 * b));
    }
}

static uint16_t ic16(hd__intcoder_t *ic, hd__dec_t *d, uint16_t pred, uint32_t ctx) {
    return (uint16_t)hd__ic_decode(ic, d, pred, ctx);
}

/* One POINT10 v2 record after the first: updates w->last.  0, or -1
 * when a lazily created model could not be allocated. */
static int p10_read(pw_t *p, hd__dec_t *d) {
    unsigned char *L = p->last;
    uint32_t changed = hd__dec_symbol(d, &p->m.changed);
    if (changed) {
        if ((changed & 32) && lazy_byte(p->m.bitbyte, &L[14], d)) return -1;
        unsigned m = hd__laz_rmap10[(L[14] >> 3) & 7][L[14] & 7];
        if (changed & 16) p->last_int[m] = ic16(&p->m.intensity, d, p->last_int[m], m < 3 ? m : 3);
        if ((changed & 8) && lazy_byte(p->m.cls, &L[15], d)) return -1;
        if (changed & 4) L[16] = (unsigned char)(hd__dec_symbol(d, &p->m.scan[(L[14] >> 6) & 1]) + L[16]);
        if ((changed & 2) && lazy_byte(p->m.user, &L[17], d)) return -1;
        if (changed & 1) {
            uint16_t ps = ic16(&p->m.psid, d, hd__ld_u16(L + 18, 0), 0);
            L[18] = (unsigned char)ps;
            L[19] = (unsigned char)(ps >> 8);
        }
    }
    unsigned r = L[14] & 7, n = (L[14] >> 3) & 7;
    unsigned m = hd__laz_rmap10[n][r], l = hd__laz_level(n, r);
    int32_t dx = hd__ic_decode(&p->m.dx, d, p->m.mx[m].v[2], n == 1);
    hd__median5_add(&p->m.mx[m], dx);
    int32_t dy = hd__ic_decode(&p->m.dy, d, p->m.my[m].v[2], (n == 1) + hd__laz_kctx(p->m.dx.k, 20));
    hd__median5_add(&p->m.my[m], dy);
    int32_t Z = hd__ic_decode(&p->m.dz, d, p->last_h[l], (n == 1) + hd__laz_kctx((p->m.dx.k + p->m.dy.k) / 2, 18));
    p->last_h[l] = Z;
    set_xyz(L, (int32_t)((uint32_t)i32_at(L) + (uint32_t)dx), (int32_t)((uint32_t)i32_at(L + 4) + (uint32_t)dy), Z);
    return 0;
}

static int32_t median3(const int32_t v[3]) {
    if (v[0] < v[1]) return v[1] < v[2] ? v[1] : v[0] < v[2] ? v[2] : v[0];
    return v[0] < v[2] ? v[0] : v[1] < v[2] ? v[2] : v[1];
}

/* One POINT10 v1 record: x, y, z first (predicted by the median of the
 * last three differences; contexts from k), then the changed fields. */
static int p10v1_read(pw_t *p, hd__dec_t *d) {
    unsigned char *L = p->last;
    int32_t dx = hd__ic_decode(&p->m.dx, d, median3(p->diff1[0]), 0);
    unsigned k = p->m.dx.k;
    int32_t dy = hd__ic_decode(&p->m.dy, d, median3(p->diff1[1]), k < 19 ? k : 19);
    k = (k + p->m.dy.k) / 2;
    int32_t Z = hd__ic_decode(&p->m.dz, d, i32_at(L + 8), k < 19 ? k : 19);
    set_xyz(L, (int32_t)((uint32_t)i32_at(L) + (uint32_t)dx), (int32_t)((uint32_t)i32_at(L + 4) + (uint32_t)dy), Z);
    uint32_t changed = hd__dec_symbol(d, &p->m.changed);
    if (changed) {
        if (changed & 32) {
            uint16_t v = ic16(&p->m.intensity, d, hd__ld_u16(L + 12, 0), 0);
            L[12] = (unsigned char)v;
            L[13] = (unsigned char)(v >> 8);
        }
        if ((changed & 16) && lazy_byte(p->m.bitbyte, &L[14], d)) return -1;
        if ((changed & 8) && lazy_byte(p->m.cls, &L[15], d)) return -1;
        if (changed & 4) L[16] = (unsigned char)hd__ic_decode(&p->m.scan1, d, L[16], k < 3);
        if ((changed & 2) && lazy_byte(p->m.user, &L[17], d)) return -1;
        if (changed & 1) {
            uint16_t ps = ic16(&p->m.psid, d, hd__ld_u16(L + 18, 0), 0);
            L[18] = (unsigned char)ps;
            L[19] = (unsigned char)(ps >> 8);
        }
    }
    p->diff1[0][p->incr1] = dx;
    p->diff1[1][p->incr1] = dy;
    p->incr1 = (p->incr1 + 1) % 3;
    return 0;
}

static uint64_t raw64(hd__dec_t *d) {
    uint64_t lo = hd__dec_raw(d, 16);
    lo |= (uint64_t)hd__dec_raw(d, 16) << 16;
    uint64_t hi = hd__dec_raw(d, 16);
    hi |= (uint64_t)hd__dec_raw(d, 16) << 16;
    return hi << 32 | lo;
}

static void gps_add(pw_t *g, unsigned s, int32_t diff) { g->t[s] = (int64_t)((uint64_t)g->t[s] + (uint64_t)(int64_t)diff); }
static int32_t times(int32_t m, int32_t v) { return (int32_t)((uint32_t)m * (uint32_t)v); }

/* GPSTIME11 v1: one sequence of times. */
static void gps1_read(pw_t *g, hd__dec_t *d) {
    int32_t *last = &g->gdiff[0];
    if (*last == 0) {
        uint32_t multi = hd__dec_symbol(d, &g->m.gzero);
        if (multi == 1) {
            *last = hd__ic_decode(&g->m.gic, d, 0, 0);
            gps_add(g, 0, *last);
        } else if (multi == 2) {
            g->t[0] = (int64_t)raw64(d);
        }
        return;
    }
    uint32_t multi = hd__dec_symbol(d, &g->m.gmulti);
    if (multi < 510) {
        int32_t diff;
        if (multi == 1) {
            diff = *last = hd__ic_decode(&g->m.gic, d, *last, 1);
            g->extreme[0] = 0;
        } else if (multi == 0) {
            diff = hd__ic_decode(&g->m.gic, d, *last / 4, 2);
            if (++g->extreme[0] > 3) *last = diff, g->extreme[0] = 0;
        } else {
            diff = hd__ic_decode(&g->m.gic, d, times((int32_t)multi, *last), multi < 10 ? 3 : multi < 50 ? 4 : 5);
            if (multi == 509 && ++g->extreme[0] > 3) *last = diff, g->extreme[0] = 0;
        }
        gps_add(g, 0, diff);
    } else if (multi == 510) {
        g->t[0] = (int64_t)raw64(d);
    }
}

/* GPSTIME11 v2: four sequences, switched between.  The values only steer
 * which models come next, but they must be followed exactly to stay in
 * step.  A valid stream switches sequence at most once per point; more is
 * an error (returns -1). */
static int gps_read(pw_t *g, hd__dec_t *d) {
    for (int round = 0; round < 4; round++) {
        unsigned L = g->glast;
        uint32_t multi;
        if (g->gdiff[L] == 0) {
            multi = hd__dec_symbol(d, &g->m.gzero);
            if (multi == 1) {
                g->gdiff[L] = hd__ic_decode(&g->m.gic, d, 0, 0);
                gps_add(g, L, g->gdiff[L]);
                g->extreme[L] = 0;
                return 0;
            }
            if (multi > 2) {
                g->glast = (L + multi - 2) & 3;
                continue;
            }
            if (multi == 0) return 0;
        } else {
            multi = hd__dec_symbol(d, &g->m.gmulti);
            if (multi == 1) {
                gps_add(g, L, hd__ic_decode(&g->m.gic, d, g->gdiff[L], 1));
                g->extreme[L] = 0;
                return 0;
            }
            if (multi < 511) { /* 500 - (-10) + 1: unchanged */
                int32_t diff;
                int extreme = 0;
                if (multi == 0) {
                    diff = hd__ic_decode(&g->m.gic, d, 0, 7);
                    extreme = 1;
                } else if (multi < 500) {
                    diff = hd__ic_decode(&g->m.gic, d, times((int32_t)multi, g->gdiff[L]), multi < 10 ? 2 : 3);
                } else if (multi == 500) {
                    diff = hd__ic_decode(&g->m.gic, d, times(500, g->gdiff[L]), 4);
                    extreme = 1;
                } else {
                    int32_t mm = 500 - (int32_t)multi;
                    extreme = mm <= -10;
                    diff = hd__ic_decode(&g->m.gic, d, times(extreme ? -10 : mm, g->gdiff[L]), extreme ? 6 : 5);
                }
                if (extreme && ++g->extreme[L] > 3) {
                    g->gdiff[L] = diff;
                    g->extreme[L] = 0;
                }
                gps_add(g, L, diff);
                return 0;
            }
            if (multi == 511) return 0;
            if (multi > 512) {
                g->glast = (L + multi - 512) & 3;
                continue;
            }
        }
        /* a full value (0diff symbol 2, multi symbol 512): a new sequence */
        g->gnext = (g->gnext + 1) & 3;
        uint32_t hi = (uint32_t)hd__ic_decode(&g->m.gic, d, (int32_t)((uint64_t)g->t[L] >> 32), 8);
        uint32_t lo = hd__dec_raw(d, 16);
        lo |= hd__dec_raw(d, 16) << 16;
        g->t[g->gnext] = (int64_t)((uint64_t)hi << 32 | lo);
        g->glast = g->gnext;
        g->gdiff[g->glast] = 0;
        g->extreme[g->glast] = 0;
        return 0;
    }
    return -1;
}

/* RGB12 v2's values (LASzip's RGB12 v2 scheme: per byte of red, its
 * change; green and blue, when the colour is not grey, predicted from red's
 * change, clamped to a byte, and coded as the correction). */
static unsigned clamp8(int v) { return v < 0 ? 0u : v > 255 ? 255u : (unsigned)v; }
static void rgb12_values(pw_t *c, hd__dec_t *d, uint32_t sym) {
    const uint16_t *last = c->rgb;
    uint16_t it[3];
    unsigned lo = sym & 1 ? (hd__dec_symbol(d, &c->m.cdiff[0]) + (last[0] & 255)) & 255 : last[0] & 255;
    unsigned hi = sym & 2 ? (hd__dec_symbol(d, &c->m.cdiff[1]) + (last[0] >> 8)) & 255 : last[0] >> 8;
    it[0] = (uint16_t)(hi << 8 | lo);
    if (sym & 64) {
        int diff = (int)(it[0] & 255) - (int)(last[0] & 255);
        unsigned g = sym & 4 ? (hd__dec_symbol(d, &c->m.cdiff[2]) + clamp8(diff + (last[1] & 255))) & 255 : last[1] & 255;
        unsigned b = last[2] & 255;
        if (sym & 16) {
            diff = (diff + ((int)g - (int)(last[1] & 255))) / 2;
            b = (hd__dec_symbol(d, &c->m.cdiff[4]) + clamp8(diff + (last[2] & 255))) & 255;
        }
        diff = (int)(it[0] >> 8) - (int)(last[0] >> 8);
        unsigned gh = sym & 8 ? (hd__dec_symbol(d, &c->m.cdiff[3]) + clamp8(diff + (last[1] >> 8))) & 255 : last[1] >> 8;
        unsigned bh = last[2] >> 8;
        if (sym & 32) {
            diff = (diff + ((int)gh - (int)(last[1] >> 8))) / 2;
            bh = (hd__dec_symbol(d, &c->m.cdiff[5]) + clamp8(diff + (last[2] >> 8))) & 255;
        }
        it[1] = (uint16_t)(gh << 8 | g);
        it[2] = (uint16_t)(bh << 8 | b);
    } else {
        it[1] = it[2] = it[0];
    }
    memcpy(c->rgb, it, sizeof it);
}

/* RGB12 v2 and v1, BYTE v2 and v1: their values never steer the stream,
 * so only their symbols are decoded. */
static void rgb_read(pw_t *c, hd__dec_t *d, int v2) {
    uint32_t sym = hd__dec_symbol(d, &c->m.used);
    if (!v2) {
        for (unsigned k = 0; k < 6; k++)
            if (sym & (1u << k)) hd__ic_decode(&c->m.cic, d, 0, k);
        return;
    }
    if (c->values) {
        rgb12_values(c, d, sym);
        return;
    }
    static const unsigned char order[6] = {0, 1, 2, 4, 3, 5};
    for (int i = 0; i < 6; i++) {
        unsigned k = order[i];
        if ((sym & (1u << k)) && (k < 2 || (sym & 64))) hd__dec_symbol(d, &c->m.cdiff[k]);
    }
}
/* BYTE v2 gives each extra byte a model of 256 symbols, created here at its
 * first symbol (a model's state depends only on the symbols coded with it,
 * so this is the model LASzip creates with the chunk); a new model is
 * uniform, so its first symbol costs 8 bits, and stopping once the decoder
 * runs past its bytes keeps the models created to about one per byte of
 * the stream, whatever the record's size.
 * 0, or -1 when a model could not be allocated. */
static int bytes_read(pw_t *c, hd__dec_t *d, int v2) {
    for (unsigned k = 0; k < c->nb && d->over <= 4; k++) {
        if (!v2) {
            hd__ic_decode(&c->bic, d, 0, k);
            continue;
        }
        hd__symmodel_t *m = lazy(&c->bm[k], 256);
        if (!m) return -1;
        uint32_t sym = hd__dec_symbol(d, m);
        if (c->values) c->blast[k] = (unsigned char)(c->blast[k] + sym);
    }
    return 0;
}

/* The end of a stream once its chunk's (or layer's) last point is decoded:
 * the decoder must stop exactly at its last byte.  LASzip's encoder ends a
 * stream with the bytes its decoder reads ahead (done() flushes one or two
 * bytes and pads with zeros to the four the decoder holds), so a stream that
 * a decoder leaves unfinished holds more points than the count says, or was
 * written with other items than the VLR lists; one that it reads past holds
 * fewer.  `what` names the stream, `unit` its container (chunk, layer),
 * `end` is its end's file offset. */
static void stream_end(job_t *j, const hd__dec_t *d, const char *what, const char *unit, long long end, size_t n) {
    if (d->over)
        fail(j, HD_EFORMAT, end, "the chunk's %s ends before its %zu point%s (the decoder ran past the %s's end)", what, n,
             n == 1 ? "" : "s", unit);
    else if (d->p != d->end)
        fail(j, HD_EFORMAT, end - (long long)(d->end - d->p),
             "%zu byte%s of the chunk's %s %s left after its %zu point%s: the point count is lower than the data, or "
             "the LASzip VLR's items are not the ones it was written with",
             (size_t)(d->end - d->p), d->end - d->p == 1 ? "" : "s", what, d->end - d->p == 1 ? "is" : "are", n,
             n == 1 ? "" : "s");
}

/* Create a pointwise chunk's models and start them from its raw first
 * point b; HD_OK or HD_ENOMEM. */
static int pointwise_start(pw_t *w, const laz_t *z, const unsigned char *b, int values) {
    int rc = pw_new(w, z);
    w->values = values;
    if (rc) return rc;
    memcpy(w->last, b, 20);
    if (z->items[0].version == 2) w->last[12] = w->last[13] = 0; /* v2: intensity starts at 0 */
    size_t off = 20;
    for (unsigned i = 1; i < z->n_items; i++) {
        if (z->items[i].type == IT_GPSTIME11) w->t[0] = (int64_t)hd__ld_u64(b + off, 0);
        if (z->items[i].type == IT_RGB12)
            for (int c = 0; c < 3; c++) w->rgb[c] = hd__ld_u16(b + off + 2 * c, 0);
        if (z->items[i].type == IT_BYTE && w->values) {
            if (!(w->blast = malloc(w->nb + 1))) return HD_ENOMEM;
            memcpy(w->blast, b + off, w->nb);
        }
        off += z->items[i].size;
    }
    return HD_OK;
}

/* The whole record of the point just decoded (v2 items): POINT10 with its
 * intensity (v2 keeps it per return context), then each item's value. */
static void record(const laz_t *z, const pw_t *w, unsigned char *out) {
    memcpy(out, w->last, 20);
    unsigned m = hd__laz_rmap10[(w->last[14] >> 3) & 7][w->last[14] & 7];
    out[12] = (unsigned char)w->last_int[m];
    out[13] = (unsigned char)(w->last_int[m] >> 8);
    size_t off = 20;
    for (unsigned i = 1; i < z->n_items; i++) {
        unsigned t = z->items[i].type;
        if (t == IT_GPSTIME11)
            for (int b = 0; b < 8; b++) out[off + b] = (unsigned char)((uint64_t)w->t[w->glast] >> (8 * b));
        else if (t == IT_RGB12)
            for (int c = 0; c < 3; c++) out[off + 2 * c] = (unsigned char)w->rgb[c], out[off + 2 * c + 1] = (unsigned char)(w->rgb[c] >> 8);
        else
            memcpy(out + off, w->blast, w->nb);
        off += z->items[i].size;
    }
}

/* Points 2..n of a pointwise chunk from d, every item in order. */
static void pointwise_points(job_t *j, pw_t *w, hd__dec_t *d, size_t n) {
    laz_t *z = j->z;
    long long at = (long long)z->start[j->chunk];
    int v2 = z->items[0].version == 2;
    for (size_t i = 1; i < n; i++) {
        if (v2 ? p10_read(w, d) : p10v1_read(w, d)) {
            fail(j, HD_ENOMEM, at, "out of memory");
            return;
        }
        for (unsigned t = 1; t < z->n_items; t++) {
            unsigned ty = z->items[t].type, iv2 = z->items[t].version == 2;
            if (ty == IT_GPSTIME11) {
                if (!iv2) {
                    gps1_read(w, d);
                } else if (gps_read(w, d)) {
                    fail(j, HD_EFORMAT, at, "point %zu: the GPS time switches sequence more than once", j->k);
                    return;
                }
            } else if (ty == IT_RGB12) {
                rgb_read(w, d, iv2);
            } else if (bytes_read(w, d, iv2)) {
                fail(j, HD_ENOMEM, at, "out of memory");
                return;
            }
        }
        if (d->over > 4) return;
        if (j->recs) record(z, w, j->recs + i * z->rec);
        if (put(j, i32_at(w->last), i32_at(w->last + 4), i32_at(w->last + 8))) return;
    }
}

/* A pointwise chunk: its raw first point, then one stream of the others.
 * A one-point chunk's stream is the four bytes the decoder reads at its
 * start (the encoder's end of an empty stream), so it is checked too. */
static void pointwise_chunk(job_t *j, const unsigned char *b, size_t nb, size_t n) {
    laz_t *z = j->z;
    long long at = (long long)z->start[j->chunk];
    if (nb < z->rec) {
        fail(j, HD_EFORMAT, at, "chunk of %zu bytes is shorter than its first point's %zu bytes", nb, z->rec);
        return;
    }
    if (put(j, i32_at(b), i32_at(b + 4), i32_at(b + 8))) return;
    if (j->recs) memcpy(j->recs, b, z->rec);
    hd__dec_t d;
    hd__dec_init(&d, b + z->rec, nb - z->rec);
    if (n > 1) {
        pw_t *w = malloc(sizeof *w);
        if (!w || pointwise_start(w, z, b, j->recs != NULL)) fail(j, HD_ENOMEM, at, "out of memory");
        else pointwise_points(j, w, &d, n);
        if (w) pw_free(w);
        free(w);
    }
    if (!j->rc) stream_end(j, &d, "compressed data", "chunk", at + (long long)nb, n);
}

/* ---- POINT14 v3/v4, layered: x and y from layer 0, z from layer 1 -------- */
typedef struct {
    int used;
    hd__p14_models_t m;
    int32_t last_z[8];
    int32_t X, Y, Z;
    unsigned r, n, gps_change;
} ctx14_t;

static void ctx14_free(ctx14_t *c) { hd__p14_models_free(&c->m); }

/* Create channel c's models and start it from a point (the chunk's first
 * point, or the previous channel's last).  Kept out of layered_points: a
 * rare step whose inlining changes the decoding loop's code (measured by
 * bench/read_bench under callgrind). */
HD__NOINLINE static int ctx14_start(ctx14_t *c, const ctx14_t *from) {
    int rc = hd__p14_models_new(&c->m);
    if (rc) return rc;
    c->X = from->X;
    c->Y = from->Y;
    c->Z = from->Z;
    c->r = from->r;
    c->n = from->n;
    c->gps_change = 0;
    for (int i = 0; i < 8; i++) c->last_z[i] = from->Z;
    c->used = 1;
    return HD_OK;
}

/* The decoding loop of layered_points: channel cur's models are started. */
static void layered_loop(job_t *j, ctx14_t *cx, unsigned cur, hd__dec_t *dxy, hd__dec_t *dz, int has_z, size_t n) {
    long long at = (long long)j->z->start[j->chunk];
    for (size_t i = 1; i < n; i++) {
        ctx14_t *c = &cx[cur];
        unsigned lpr = (c->r == 1) + 2 * (c->r >= c->n) + 4 * c->gps_change;
        uint32_t changed = hd__dec_symbol(dxy, &c->m.changed[lpr]);
        if (changed & 64) {
            unsigned next = (cur + hd__dec_symbol(dxy, &c->m.scanner) + 1) & 3;
            if (!cx[next].used && ctx14_start(&cx[next], c)) {
                fail(j, HD_ENOMEM, at, "out of memory");
                return;
            }
            cur = next;
            c = &cx[cur];
        }
        if (j->chan) j->chan[i] = (unsigned char)cur;
        unsigned gps = (changed >> 4) & 1;
        unsigned last_n = c->n, last_r = c->r, nn = last_n, r = last_r;
        if (changed & 4) {
            hd__symmodel_t *m = lazy(&c->m.nret[last_n], 16);
            if (!m) {
                fail(j, HD_ENOMEM, at, "out of memory");
                return;
            }
            nn = hd__dec_symbol(dxy, m);
        }
        switch (changed & 3) {
        case 1: r = (last_r + 1) & 15; break;
        case 2: r = (last_r + 15) & 15; break;
        case 3:
            if (gps) {
                hd__symmodel_t *m = lazy(&c->m.rnum[last_r], 16);
                if (!m) {
                    fail(j, HD_ENOMEM, at, "out of memory");
                    return;
                }
                r = hd__dec_symbol(dxy, m);
            } else {
                r = (last_r + hd__dec_symbol(dxy, &c->m.rn_same) + 2) & 15;
            }
            break;
        default: break;
        }
        c->n = nn;
        c->r = r;
        unsigned m = hd__laz_rmap14[nn][r], l = hd__laz_level(nn, r), mi = m << 1 | gps;
        int32_t dx = hd__ic_decode(&c->m.dx, dxy, c->m.mx[mi].v[2], nn == 1);
        c->X = (int32_t)((uint32_t)c->X + (uint32_t)dx);
        hd__median5_add(&c->m.mx[mi], dx);
        int32_t dy = hd__ic_decode(&c->m.dy, dxy, c->m.my[mi].v[2], (nn == 1) + hd__laz_kctx(c->m.dx.k, 20));
        c->Y = (int32_t)((uint32_t)c->Y + (uint32_t)dy);
        hd__median5_add(&c->m.my[mi], dy);
        if (has_z) {
            c->Z = hd__ic_decode(&c->m.dz, dz, c->last_z[l], (nn == 1) + hd__laz_kctx((c->m.dx.k + c->m.dy.k) / 2, 18));
            c->last_z[l] = c->Z;
        }
        c->gps_change = gps;
        if (dxy->over > 4 || dz->over > 4) break;
        if (put(j, c->X, c->Y, c->Z)) return;
    }
}

/* A layered chunk's header: its raw first point (stored), its own point
 * count (the table's), its layer sizes, which fill the chunk exactly; the
 * sizes of the x/y and z layers in *nxy, *nz.  0 when it failed. */
static int layered_head(job_t *j, const unsigned char *b, size_t nb, size_t n, size_t *nxy, size_t *nz) {
    laz_t *z = j->z;
    long long at = (long long)z->start[j->chunk];
    size_t head = z->rec + 4 + 4 * (size_t)z->n_layers;
    if (nb < head) {
        fail(j, HD_EFORMAT, at, "chunk of %zu bytes is shorter than its first point and layer sizes (%zu bytes)", nb, head);
        return 0;
    }
    if (put(j, i32_at(b), i32_at(b + 4), i32_at(b + 8))) return 0;
    uint32_t stored = hd__ld_u32(b + z->rec, 0);
    if (stored != n) {
        fail(j, HD_EFORMAT, at + (long long)z->rec, "the chunk says it holds %u points, the chunk table %zu", stored, n);
        return 0;
    }
    uint64_t total = 0;
    for (unsigned i = 0; i < z->n_layers; i++) total += hd__ld_u32(b + z->rec + 4 + 4 * i, 0);
    if (total != nb - head) {
        fail(j, HD_EFORMAT, at + (long long)z->rec + 4, "the chunk's layers %s %llu bytes, it has %zu after its header",
             total > nb - head ? "need" : "fill only", (unsigned long long)total, nb - head);
        return 0;
    }
    *nxy = hd__ld_u32(b + z->rec + 4, 0);
    *nz = hd__ld_u32(b + z->rec + 8, 0);
    return 1;
}

/* Points 2..n of a layered chunk whose raw first point is b: x and y (with
 * the channel and returns that choose their models) from dxy, z from dz
 * when has_z (an empty z layer: z constant in the chunk). */
static void layered_points(job_t *j, const unsigned char *b, hd__dec_t *dxy, hd__dec_t *dz, int has_z, size_t n) {
    long long at = (long long)j->z->start[j->chunk];
    ctx14_t *cx = calloc(4, sizeof *cx);
    if (!cx) {
        fail(j, HD_ENOMEM, at, "out of memory");
        return;
    }
    ctx14_t first = {0};
    first.X = i32_at(b);
    first.Y = i32_at(b + 4);
    first.Z = i32_at(b + 8);
    first.r = b[14] & 15;
    first.n = b[14] >> 4;
    unsigned cur = (b[15] >> 4) & 3;
    if (j->chan) j->chan[0] = (unsigned char)cur;
    if (ctx14_start(&cx[cur], &first)) fail(j, HD_ENOMEM, at, "out of memory");
    else layered_loop(j, cx, cur, dxy, dz, has_z, n);
    for (int c = 0; c < 4; c++) ctx14_free(&cx[c]);
    free(cx);
}

/* A layered chunk: its header, then the x/y and z layers decoded, each
 * used up exactly when it has bytes (a one-point chunk's layers are the
 * four bytes of an empty stream, or nothing); the other layers are
 * stepped over by their sizes. */
static void layered_chunk(job_t *j, const unsigned char *b, size_t nb, size_t n) {
    laz_t *z = j->z;
    long long at = (long long)z->start[j->chunk];
    size_t nxy = 0, nz = 0, head = z->rec + 4 + 4 * (size_t)z->n_layers;
    if (!layered_head(j, b, nb, n, &nxy, &nz)) return;
    hd__dec_t dxy, dz;
    hd__dec_init(&dxy, b + head, nxy);
    hd__dec_init(&dz, b + head + nxy, nz);
    if (n > 1) layered_points(j, b, &dxy, &dz, nz > 0, n);
    if (!j->rc && (nxy || n > 1)) stream_end(j, &dxy, "x/y layer", "layer", at + (long long)(head + nxy), n);
    if (!j->rc && nz) stream_end(j, &dz, "z layer", "layer", at + (long long)(head + nxy + nz), n);
}

static void decode_chunk(void *ctx, size_t task, int worker) {
    (void)worker;
    laz_t *z = ctx;
    /* outside a range read: not decoded, but for the last chunk, where a
     * header count lower than the data shows (see hd__read_laz) */
    if ((z->first[task + 1] <= z->lo || z->first[task] >= z->hi) && task + 1 < z->n_chunks) {
        z->rc[task] = 0;
        return;
    }
    job_t j = {z, task, z->r->sink, z->r->sink->dtype == HD_FLOAT32 ? (double)FLT_MAX : HD_MAX_COORD,
               (size_t)z->first[task], 0, -1, "", NULL, NULL};
    const unsigned char *b = z->d + z->start[task];
    size_t nb = (size_t)(z->start[task + 1] - z->start[task]), n = (size_t)(z->first[task + 1] - z->first[task]);
    if (z->layered) layered_chunk(&j, b, nb, n);
    else pointwise_chunk(&j, b, nb, n);
    z->rc[task] = j.rc;
    z->at[task] = j.at;
    memcpy(z->msg[task], j.msg, sizeof j.msg);
}

/* ---- the VLR, the chunk table ----------------------------------------------- */
/* The VLRs from h->header: 1 with *p, *n at the LASzip VLR's header and
 * data size; 0 when none is among them; -1 with *p at VLR *i (from 0)
 * when its header does not fit before the points, -2 when its data does
 * not (*n its size). */
static int scan_vlrs(const unsigned char *d, const hd__las_header_t *h, size_t *p, size_t *n, uint32_t *i) {
    *p = h->header;
    for (*i = 0; *i < h->n_vlr; ++*i) {
        if (*p + 54 > h->offset) return -1;
        *n = hd__ld_u16(d + *p + 20, 0);
        if (*p + 54 + *n > h->offset) return -2;
        if (memcmp(d + *p + 2, "laszip encoded", 14) == 0 && d[*p + 16] == 0 && hd__ld_u16(d + *p + 18, 0) == 22204) return 1;
        *p += 54 + *n;
    }
    return 0;
}

int hd__laz_vlr_present(const unsigned char *d, const hd__las_header_t *h) {
    size_t p, n;
    uint32_t i;
    return scan_vlrs(d, h, &p, &n, &i) == 1;
}

static int find_vlr(laz_t *z, const hd__las_header_t *h, const unsigned char **vlr, size_t *len, size_t *vlr_at) {
    hd__read_t *r = z->r;
    size_t p = 0, n = 0;
    uint32_t i = 0;
    int found = scan_vlrs(z->d, h, &p, &n, &i);
    if (found == -1)
        return hd__io_err_at(r, HD_EFORMAT, (long long)p, "VLR %u of %u does not fit before the point data at byte %zu", i + 1,
                             h->n_vlr, h->offset);
    if (found == -2)
        return hd__io_err_at(r, HD_EFORMAT, (long long)p + 20, "VLR %u's %zu bytes run past the point data at byte %zu", i + 1, n,
                             h->offset);
    if (found == 1) {
        *vlr = z->d + p + 54;
        *len = n;
        *vlr_at = p + 54;
        return HD_OK;
    }
    return hd__io_err_at(r, HD_EFORMAT, 104,
                         "the point format says compressed (LAZ) but no LASzip VLR (user 'laszip encoded', record 22204) is "
                         "among the %u VLRs",
                         h->n_vlr);
}

static int parse_vlr(laz_t *z, const hd__las_header_t *h, uint32_t *chunk_size) {
    hd__read_t *r = z->r;
    const unsigned char *v = NULL;
    size_t len = 0, at = 0;
    int rc = find_vlr(z, h, &v, &len, &at);
    if (rc) return rc;
    if (len < 34) return hd__io_err_at(r, HD_EFORMAT, (long long)at, "LASzip VLR of %zu bytes (34 at least)", len);
    unsigned compressor = hd__ld_u16(v, 0), coder = hd__ld_u16(v + 2, 0);
    *chunk_size = hd__ld_u32(v + 12, 0);
    z->n_items = hd__ld_u16(v + 32, 0);
    if (coder != 0)
        return hd__io_err_at(r, HD_EUNSUPPORTED, (long long)at + 2, "LASzip coder %u (0, arithmetic, is the one defined)", coder);
    if (compressor < 1 || compressor > 3)
        return hd__io_err_at(r, HD_EUNSUPPORTED, (long long)at,
                             "LASzip compressor %u (1 pointwise, 2 pointwise chunked, 3 layered chunked are read)", compressor);
    z->layered = compressor == 3;
    z->chunked = compressor >= 2;
    if (z->n_items == 0 || z->n_items > 32 || 34 + 6 * (size_t)z->n_items > len)
        return hd__io_err_at(r, HD_EFORMAT, (long long)at + 32, "LASzip VLR lists %u items in %zu bytes", z->n_items, len);
    size_t sum = 0;
    z->n_layers = 0;
    for (unsigned i = 0; i < z->n_items; i++) {
        item_t *it = &z->items[i];
        const unsigned char *q = v + 34 + 6 * i;
        it->type = hd__ld_u16(q, 0);
        it->size = hd__ld_u16(q + 2, 0);
        it->version = hd__ld_u16(q + 4, 0);
        long long where = (long long)(at + 34 + 6 * i);
        sum += it->size;
        static const unsigned char need[15] = {0, 0, 0, 0, 0, 0, 20, 8, 6, 29, 30, 6, 8, 29, 0};
        int ok, first = i == 0;
        if (!z->layered) {
            ok = (first ? it->type == IT_POINT10 : (it->type == IT_GPSTIME11 || it->type == IT_RGB12 || it->type == IT_BYTE)) &&
                 (it->version == 1 || it->version == 2);
        } else {
            ok = (first ? it->type == IT_POINT14
                        : (it->type == IT_RGB14 || it->type == IT_RGBNIR14 || it->type == IT_WAVE14 || it->type == IT_BYTE14)) &&
                 (it->version == 3 || it->version == 4);
            if (ok) z->n_layers += it->type == IT_POINT14 ? 9 : it->type == IT_RGBNIR14 ? 2 : it->type == IT_BYTE14 ? it->size : 1;
        }
        if (!ok)
            return hd__io_err_at(r, HD_EUNSUPPORTED, where,
                                 "LASzip item %u is type %u version %u; read are %s", i + 1, it->type, it->version,
                                 z->layered ? "POINT14 first, then RGB14, RGBNIR14, WAVEPACKET14, BYTE14 (versions 3, 4)"
                                            : "POINT10 first, then GPSTIME11, RGB12, BYTE (versions 1, 2)");
        for (unsigned k = 0; k < i; k++)
            if (z->items[k].type == it->type)
                return hd__io_err_at(r, HD_EFORMAT, where, "LASzip item %u repeats item %u's type %u", i + 1, k + 1, it->type);
        if (it->type < 15 && need[it->type] && it->size != need[it->type])
            return hd__io_err_at(r, HD_EFORMAT, where + 2, "LASzip item %u (type %u) has size %u, not %u", i + 1, it->type, it->size,
                                 need[it->type]);
        if ((it->type == IT_BYTE || it->type == IT_BYTE14) && it->size == 0)
            return hd__io_err_at(r, HD_EFORMAT, where + 2, "LASzip item %u: extra bytes of size 0", i + 1);
    }
    if (sum != h->rec)
        return hd__io_err_at(r, HD_EFORMAT, (long long)at + 34,
                             "the LASzip items add up to %zu bytes per point, the header's record length is %zu", sum, h->rec);
    if ((h->fmt >= 6) != z->layered)
        return hd__io_err_at(r, HD_EFORMAT, 104, "point format %u with the LASzip %s compressor", h->fmt,
                             z->layered ? "layered" : "pointwise");
    return HD_OK;
}

/* Chunk c of nc, at `at`, claims more than z->per_byte points a byte.
 * Above HD_LAZ_POINTS_PER_BYTE_MAX no stream can hold them (HD_EFORMAT);
 * below, the file may be degenerate data, refused by the limit that bounds
 * its memory, which the message says how to raise (HD_EUNSUPPORTED). */
static int too_dense(laz_t *z, long long at, size_t c, size_t nc, uint64_t pts, uint64_t bytes) {
    if (pts > bytes * HD_LAZ_POINTS_PER_BYTE_MAX)
        return hd__io_err_at(z->r, HD_EFORMAT, at, "chunk %zu of %zu claims %llu points in %llu bytes (no stream holds more than %d a byte)",
                             c, nc, (unsigned long long)pts, (unsigned long long)bytes, HD_LAZ_POINTS_PER_BYTE_MAX);
    return hd__io_err_at(z->r, HD_EUNSUPPORTED, at,
                         "chunk %zu of %zu claims %llu points in %llu bytes, %.0f a byte: above the limit of %u points a "
                         "compressed byte (%s), which bounds the memory a LAZ file may ask for; raise it up to %d with "
                         "--laz-points-per-byte N (read option laz_points_per_byte)",
                         c, nc, (unsigned long long)pts, (unsigned long long)bytes, ceil((double)pts / (double)bytes), z->per_byte,
                         z->per_byte == HD_LAZ_POINTS_PER_BYTE ? "the default" : "as asked", HD_LAZ_POINTS_PER_BYTE_MAX);
}

static int read_table(laz_t *z, const hd__las_header_t *h, uint32_t chunk_size) {
    hd__read_t *r = z->r;
    size_t data = h->offset + 8;
    if (data > z->size) return hd__io_err_at(r, HD_EFORMAT, (long long)h->offset, "file ends before the chunk table's offset");
    int64_t tab = (int64_t)hd__ld_u64(z->d + h->offset, 0);
    long long tab_from = (long long)h->offset;
    if (tab == 0 || tab == -1) { /* written without seeking: the offset is at the end */
        tab = (int64_t)hd__ld_u64(z->d + z->size - 8, 0);
        tab_from = (long long)z->size - 8;
    }
    if (tab < (int64_t)data || (uint64_t)tab > z->size - 8)
        return hd__io_err_at(r, HD_EFORMAT, tab_from, "chunk table at byte %lld is outside [%zu, %zu]", (long long)tab, data,
                             z->size - 8);
    size_t t = (size_t)tab;
    uint32_t version = hd__ld_u32(z->d + t, 0), nc = hd__ld_u32(z->d + t + 4, 0);
    if (version != 0) return hd__io_err_at(r, HD_EUNSUPPORTED, (long long)t, "chunk table version %u (0 is defined)", version);
    int variable = chunk_size == 0 || chunk_size == 0xFFFFFFFFu;
    uint64_t count = h->count;
    if (nc == 0 && count > 0) return hd__io_err_at(r, HD_EFORMAT, (long long)t + 4, "chunk table with no chunks for %llu points", (unsigned long long)count);
    if (nc > t - data)
        return hd__io_err_at(r, HD_EFORMAT, (long long)t + 4, "%u chunks in the %zu bytes before the chunk table", nc, t - data);
    if (!variable) {
        uint64_t need = (count + chunk_size - 1) / chunk_size;
        if (nc != need)
            return hd__io_err_at(r, HD_EFORMAT, (long long)t + 4, "%u chunks for %llu points in chunks of %u (%llu expected)", nc,
                                 (unsigned long long)count, chunk_size, (unsigned long long)need);
    }
    z->n_chunks = nc;
    z->start = hd__malloc_array((size_t)nc + 1, sizeof(uint64_t));
    z->first = hd__malloc_array((size_t)nc + 1, sizeof(uint64_t));
    if (!z->start || !z->first) return hd__io_err(r, HD_ENOMEM, "out of memory for %u chunks", nc);
    hd__intcoder_t ic;
    if (hd__intcoder_new(&ic, 32, 2)) return hd__io_err(r, HD_ENOMEM, "out of memory");
    hd__dec_t d;
    hd__dec_init(&d, z->d + t + 8, z->size - t - 8);
    uint32_t pc = 0, pb = 0;
    z->start[0] = data;
    z->first[0] = 0;
    int rc = HD_OK;
    for (uint32_t i = 0; i < nc && rc == HD_OK; i++) {
        uint32_t pts = chunk_size;
        if (variable) pts = pc = (uint32_t)hd__ic_decode(&ic, &d, (int32_t)pc, 0);
        else if (i + 1 == nc) pts = (uint32_t)(count - (uint64_t)chunk_size * i);
        uint32_t bytes = pb = (uint32_t)hd__ic_decode(&ic, &d, (int32_t)pb, 1);
        z->start[i + 1] = z->start[i] + bytes;
        z->first[i + 1] = z->first[i] + pts;
        if (d.over)
            rc = hd__io_err_at(r, HD_EFORMAT, (long long)z->size, "the chunk table ends inside its entry %u of %u", i + 1, nc);
        else if (bytes == 0 || pts == 0)
            rc = hd__io_err_at(r, HD_EFORMAT, (long long)t + 8, "chunk %u of %u has %s", i + 1, nc, bytes ? "no points" : "no bytes");
        else if (z->start[i + 1] > (uint64_t)t)
            rc = hd__io_err_at(r, HD_EFORMAT, (long long)z->start[i],
                               "chunk %u of %u (%u bytes from here) runs past the chunk table at byte %zu", i + 1, nc, bytes, t);
        else if (z->first[i + 1] > count)
            rc = hd__io_err_at(r, HD_EFORMAT, (long long)t + 8, "the chunks hold more than the header's %llu points",
                               (unsigned long long)count);
        else if (pts > (uint64_t)bytes * z->per_byte)
            rc = too_dense(z, (long long)z->start[i], i + 1, nc, pts, bytes);
    }
    hd__intcoder_free(&ic);
    z->start_table = t;
    z->table_end = (size_t)(d.p - z->d); /* a stream is used up exactly by its decoder */
    if (rc == HD_OK && z->first[nc] != count)
        rc = hd__io_err_at(r, HD_EFORMAT, (long long)t + 8, "the chunks hold %llu points, the header says %llu",
                           (unsigned long long)z->first[nc], (unsigned long long)count);
    return rc;
}

/* LASzip 1.x (compressor 1): no chunk table, one stream from the point
 * offset to the end of the file or the extended VLRs. */
static int one_chunk(laz_t *z, const hd__las_header_t *h) {
    size_t end = h->evlr > h->offset && h->evlr < z->size ? (size_t)h->evlr : z->size;
    z->n_chunks = 1;
    z->start = hd__malloc_array(2, sizeof(uint64_t));
    z->first = hd__malloc_array(2, sizeof(uint64_t));
    if (!z->start || !z->first) return hd__io_err(z->r, HD_ENOMEM, "out of memory");
    z->start[0] = h->offset;
    z->start[1] = end;
    z->first[0] = 0;
    z->first[1] = h->count;
    if (h->count > (uint64_t)(end - h->offset) * z->per_byte) return too_dense(z, 107, 1, 1, h->count, end - h->offset);
    return HD_OK;
}

/* The per-chunk outcome arrays; HD_OK or the error. */
static int alloc_outcomes(laz_t *z) {
    z->rc = hd__malloc_array(z->n_chunks, sizeof *z->rc);
    z->at = hd__malloc_array(z->n_chunks, sizeof *z->at);
    z->msg = hd__malloc_array(z->n_chunks, sizeof *z->msg);
    return z->rc && z->at && z->msg ? HD_OK : hd__io_err(z->r, HD_ENOMEM, "out of memory");
}

/* The first failing chunk in file order, as the error; HD_OK when none of
 * the first n failed. */
static int first_failure(laz_t *z, size_t n) {
    for (size_t c = 0; c < n; c++)
        if (z->rc[c]) return hd__io_err_at(z->r, z->rc[c], z->at[c], "chunk %zu of %zu: %s", c + 1, z->n_chunks, z->msg[c]);
    return HD_OK;
}

/* hd_read_count: the header's count once the chunk table is checked, every
 * layered chunk's own count matches it, and the last chunk, where a header
 * count lower than the data shows (fixed chunk sizes put the difference
 * there; LASzip 1.x has no other), decodes to exactly its points.  No
 * point is kept. */
static int count_laz(laz_t *z, const hd__las_header_t *h) {
    z->lo = z->hi = 0;
    int rc = alloc_outcomes(z);
    for (size_t c = 0; rc == HD_OK && z->layered && c + 1 < z->n_chunks; c++) {
        uint64_t stored = z->start[c + 1] - z->start[c] >= z->rec + 4 ? hd__ld_u32(z->d + z->start[c] + z->rec, 0) : 0;
        if (stored != z->first[c + 1] - z->first[c])
            rc = hd__io_err_at(z->r, HD_EFORMAT, (long long)(z->start[c] + z->rec),
                               "chunk %zu of %zu says it holds %llu points, the chunk table %llu", c + 1, z->n_chunks,
                               (unsigned long long)stored, (unsigned long long)(z->first[c + 1] - z->first[c]));
    }
    if (rc == HD_OK) {
        memset(z->rc, 0, z->n_chunks * sizeof *z->rc);
        decode_chunk(z, z->n_chunks - 1, 0);
        rc = first_failure(z, z->n_chunks);
    }
    if (rc == HD_OK) {
        z->r->total = h->count;
        rc = HD__COUNTED;
    }
    return rc;
}

/* The points [z->lo, z->hi) into the sink.  Up to HD__LAZ_EAGER_PER_BYTE
 * points per byte of chunk data the result is allocated at once and the
 * chunks decoded in parallel; above, chunks are decoded one after the
 * other and the result grows as points are decoded, so a file whose claims
 * its bytes do not back fails before allocating them. */
static int decode_laz(laz_t *z, const hd__las_header_t *h) {
    hd__read_t *r = z->r;
    z->grow = h->count > (z->start[z->n_chunks] - z->start[0]) * HD__LAZ_EAGER_PER_BYTE;
    int rc = hd__sink_reserve(r->sink, z->grow ? 0 : (size_t)(z->hi - z->lo));
    if (rc) return hd__io_err(r, rc, "cannot allocate %llu points: %s", (unsigned long long)h->count, hd_strerror(rc));
    if ((rc = alloc_outcomes(z)) != HD_OK) return rc;
    if (!z->grow) hd__parallel_for(hd__thread_count(r->threads, z->n_chunks), z->n_chunks, decode_chunk, z);
    size_t done = z->grow ? 0 : z->n_chunks;
    while (done < z->n_chunks) {
        decode_chunk(z, done, 0);
        if (z->rc[done++]) break;
    }
    rc = first_failure(z, done);
    if (rc == HD_OK) r->sink->count = (size_t)(z->hi - z->lo);
    return rc;
}

/* A range read keeps [lo, hi) and decodes only the chunks that meet it
 * (and the last). */
static int laz_range(laz_t *z, const hd__las_header_t *h) {
    hd__read_t *r = z->r;
    const hd_read_options_t *o = r->opt;
    z->lo = 0;
    z->hi = h->count;
    if (!o->range_count || o->mesh != HD_MESH_VERTICES) return HD_OK;
    if (o->range_first > h->count || o->range_count > h->count - o->range_first)
        return hd__io_err(r, HD_ERANGE, "points [%llu, %llu) asked of a file of %llu points", (unsigned long long)o->range_first,
                          (unsigned long long)(o->range_first + o->range_count), (unsigned long long)h->count);
    z->lo = o->range_first;
    z->hi = o->range_first + o->range_count;
    r->ranged = 1;
    return HD_OK;
}

int hd__read_laz(hd__read_t *r, const hd__las_header_t *h) {
    laz_t z;
    memset(&z, 0, sizeof z);
    z.r = r;
    z.d = r->f->data;
    z.size = r->f->size;
    z.rec = h->rec;
    for (int c = 0; c < 3; c++) {
        z.scale[c] = h->scale[c];
        z.shift[c] = h->shift[c];
    }
    z.per_byte = r->opt->laz_points_per_byte ? r->opt->laz_points_per_byte : HD_LAZ_POINTS_PER_BYTE;
    if (z.per_byte > HD_LAZ_POINTS_PER_BYTE_MAX)
        return hd__io_err(r, HD_EINVAL, "laz_points_per_byte %u is above %d (no LAZ stream holds more points a byte)", z.per_byte,
                          HD_LAZ_POINTS_PER_BYTE_MAX);
    uint32_t chunk_size = 0;
    int rc = parse_vlr(&z, h, &chunk_size);
    if (rc == HD_OK && h->count == 0) return r->count_only ? HD__COUNTED : HD_OK; /* total stays 0 */
    if (rc == HD_OK && z.chunked) rc = read_table(&z, h, chunk_size);
    if (rc == HD_OK && !z.chunked) rc = one_chunk(&z, h);
    if (rc == HD_OK && r->sink->count != 0) rc = hd__io_err(r, HD_EINVAL, "internal: LAZ points into a non-empty sink");
    if (rc == HD_OK && r->count_only) rc = count_laz(&z, h);
    else if (rc == HD_OK && (rc = laz_range(&z, h)) == HD_OK) rc = decode_laz(&z, h);
    free(z.start);
    free(z.first);
    free(z.rc);
    free(z.at);
    free(z.msg);
    return rc;
}

/* ---- for the LAZ writer (write_laz.c) ---------------------------------------- */
void hd__laz_chunks_free(hd__laz_chunks_t *c) {
    free(c->start);
    free(c->first);
    c->start = c->first = NULL;
}

int hd__laz_chunks(hd__read_t *r, const hd__las_header_t *h, hd__laz_chunks_t *out) {
    laz_t z;
    memset(&z, 0, sizeof z);
    memset(out, 0, sizeof *out);
    z.r = r;
    z.d = r->f->data;
    z.size = r->f->size;
    z.rec = h->rec;
    z.per_byte = r->opt->laz_points_per_byte ? r->opt->laz_points_per_byte : HD_LAZ_POINTS_PER_BYTE;
    uint32_t chunk_size = 0;
    int rc = parse_vlr(&z, h, &chunk_size);
    if (rc == HD_OK && h->count && z.chunked) rc = read_table(&z, h, chunk_size);
    if (rc == HD_OK) {
        const unsigned char *v;
        size_t len, at;
        find_vlr(&z, h, &v, &len, &at);
        out->vlr_at = at;
        out->vlr_len = len;
        out->layered = z.layered;
        out->chunked = z.chunked;
        out->n_layers = z.n_layers;
        out->n_items = z.n_items;
        for (unsigned i = 0; i < z.n_items; i++) {
            out->type[i] = z.items[i].type;
            out->size[i] = z.items[i].size;
            out->version[i] = z.items[i].version;
        }
        out->chunk_size = chunk_size;
        out->n_chunks = h->count ? z.n_chunks : 0;
        out->start = z.start;
        out->first = z.first;
        z.start = z.first = NULL;
        /* the table's end: where the decoder of its entries stopped */
        out->table = h->count ? z.start_table : h->offset + 8;
        out->table_end = h->count ? z.table_end : h->offset + 8;
    }
    free(z.start);
    free(z.first);
    return rc;
}

/* A laz_t over the chunks c found by hd__laz_chunks (borrowed), decoding
 * without keeping points. */
static void laz_over(laz_t *z, hd__read_t *r, const hd__las_header_t *h, const hd__laz_chunks_t *c) {
    memset(z, 0, sizeof *z);
    z->r = r;
    z->d = r->f->data;
    z->size = r->f->size;
    z->rec = h->rec;
    z->layered = c->layered;
    z->n_layers = c->n_layers;
    z->n_items = c->n_items;
    for (unsigned i = 0; i < c->n_items; i++) z->items[i] = (item_t){c->type[i], c->size[i], c->version[i]};
    z->start = c->start;
    z->first = c->first;
    z->n_chunks = c->n_chunks;
    z->lo = z->hi = 0; /* decoded, not kept */
}

int hd__laz_chunk_channels(hd__read_t *r, const hd__las_header_t *h, const hd__laz_chunks_t *c, size_t chunk,
                           unsigned char *chan) {
    laz_t z;
    laz_over(&z, r, h, c);
    job_t j = {&z, chunk, r->sink, HD_MAX_COORD, (size_t)c->first[chunk], 0, -1, "", chan, NULL};
    const unsigned char *b = z.d + c->start[chunk];
    layered_chunk(&j, b, (size_t)(c->start[chunk + 1] - c->start[chunk]), (size_t)(c->first[chunk + 1] - c->first[chunk]));
    if (j.rc) return hd__io_err_at(r, j.rc, j.at, "chunk %zu of %zu: %s", chunk + 1, c->n_chunks, j.msg);
    return HD_OK;
}

int hd__laz_chunk_records(hd__read_t *r, const hd__las_header_t *h, const hd__laz_chunks_t *c, size_t chunk,
                          unsigned char *recs) {
    const unsigned char *b = r->f->data + c->start[chunk];
    size_t nb = (size_t)(c->start[chunk + 1] - c->start[chunk]), n = (size_t)(c->first[chunk + 1] - c->first[chunk]);
    if (c->layered) { /* every layer (laz14.c) */
        hd__laz14_items_t it = {c->n_items, {0}, {0}, {0}};
        for (unsigned i = 0; i < c->n_items; i++) {
            it.type[i] = c->type[i];
            it.size[i] = c->size[i];
            it.version[i] = c->version[i];
        }
        char msg[320];
        size_t at = 0;
        int rc = hd__laz14_decode(b, nb, n, h->rec, &it, recs, msg, sizeof msg, &at);
        if (rc) return hd__io_err_at(r, rc, (long long)(c->start[chunk] + at), "chunk %zu of %zu: %s", chunk + 1, c->n_chunks, msg);
        return HD_OK;
    }
    laz_t z;
    laz_over(&z, r, h, c);
    job_t j = {&z, chunk, r->sink, HD_MAX_COORD, (size_t)c->first[chunk], 0, -1, "", NULL, recs};
    pointwise_chunk(&j, z.d + c->start[chunk], (size_t)(c->start[chunk + 1] - c->start[chunk]),
                    (size_t)(c->first[chunk + 1] - c->first[chunk]));
    if (j.rc) return hd__io_err_at(r, j.rc, j.at, "chunk %zu of %zu: %s", chunk + 1, c->n_chunks, j.msg);
    return HD_OK;
}
