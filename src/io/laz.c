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
 * its size.  COPC files are layered LAZ with variable chunk sizes.
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
 * points than HD__LAZ_POINTS_PER_BYTE per byte of it (a point costs at
 * least a few thousandths of a bit in the format's most skewed models;
 * the limit is generous for real files, see docs/formats.md); a chunk's
 * layer sizes fit inside it; a stream that reads past its bytes is an
 * error (a valid stream never does: the encoder's last bytes and padding
 * keep the decoder within them).  Chunks are decoded in parallel, each by
 * itself with models of its own, straight into its window of the sink;
 * the first failing chunk in file order is the error, so the message does
 * not depend on the thread count.  Coordinates are X * scale + offset in
 * double, as for LAS.
 */
#include "io.h"
#include "lazcoder.h"

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
    int layered;
    size_t rec;
    item_t items[32];
    unsigned n_items, n_layers;
    size_t n_chunks;
    uint64_t *start; /* n_chunks + 1 byte offsets */
    uint64_t *first; /* n_chunks + 1 cumulative point counts */
    double scale[3], shift[3];
    /* per chunk: the first problem */
    int *rc;
    long long *at;
    char (*msg)[200];
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
    char msg[200];
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
    double p[3] = {(double)X * z->scale[0] + z->shift[0], (double)Y * z->scale[1] + z->shift[1],
                   (double)Z * z->scale[2] + z->shift[2]};
    if (!(fabs(p[0]) <= j->lim && fabs(p[1]) <= j->lim && fabs(p[2]) <= j->lim)) {
        int code = hd__point_valid(p, j->s->dtype), c = 0;
        while (c < 2 && hd__point_valid((double[3]){p[c], 0, 0}, j->s->dtype) == HD_OK) c++;
        return fail(j, code, (long long)z->start[j->chunk], "point %zu (in the chunk starting here): %s (%c = %g)", j->k,
                    hd__point_problem(code), "xyz"[c], p[c]);
    }
    hd__sink_set(j->s, j->k++, p);
    return 0;
}

static int32_t i32_at(const unsigned char *p) { return (int32_t)hd__ld_u32(p, 0); }

/* ---- POINT10 v2 and the pointwise items ------------------------------------ */
typedef struct {
    hd__symmodel_t changed, scan[2];
    hd__symmodel_t *bitbyte[256], *cls[256], *user[256];
    hd__intcoder_t intensity, psid, dx, dy, dz;
    hd__median5_t mx[16], my[16];
    uint16_t last_int[16];
    int32_t last_h[8];
    unsigned char last[20];
} p10_t;

typedef struct {
    hd__symmodel_t multi, zero;
    hd__intcoder_t ic;
    int64_t t[4];
    int32_t diff[4];
    int extreme[4];
    unsigned last, next;
} gps_t;

typedef struct {
    hd__symmodel_t used, diff[6];
} rgb_t;

typedef struct {
    unsigned n;
    hd__symmodel_t *m; /* n models */
} bytes_t;

/* Every model of a chunk, zeroed first so that freeing is always safe. */
typedef struct {
    p10_t p;
    gps_t g;
    rgb_t c;
    bytes_t b;
    int has_g, has_c, has_b;
} pw_t;

static void pw_free(pw_t *w) {
    hd__symmodel_free(&w->p.changed);
    hd__symmodel_free(&w->p.scan[0]);
    hd__symmodel_free(&w->p.scan[1]);
    for (int i = 0; i < 256; i++) {
        hd__symmodel_t **t[3] = {w->p.bitbyte, w->p.cls, w->p.user};
        for (int a = 0; a < 3; a++)
            if (t[a][i]) {
                hd__symmodel_free(t[a][i]);
                free(t[a][i]);
            }
    }
    hd__intcoder_free(&w->p.intensity);
    hd__intcoder_free(&w->p.psid);
    hd__intcoder_free(&w->p.dx);
    hd__intcoder_free(&w->p.dy);
    hd__intcoder_free(&w->p.dz);
    hd__symmodel_free(&w->g.multi);
    hd__symmodel_free(&w->g.zero);
    hd__intcoder_free(&w->g.ic);
    hd__symmodel_free(&w->c.used);
    for (int i = 0; i < 6; i++) hd__symmodel_free(&w->c.diff[i]);
    if (w->b.m)
        for (unsigned i = 0; i < w->b.n; i++) hd__symmodel_free(&w->b.m[i]);
    free(w->b.m);
}

static int pw_new(pw_t *w, const laz_t *z) {
    memset(w, 0, sizeof *w);
    int rc = hd__symmodel_new(&w->p.changed, 64);
    rc = rc ? rc : hd__symmodel_new(&w->p.scan[0], 256);
    rc = rc ? rc : hd__symmodel_new(&w->p.scan[1], 256);
    rc = rc ? rc : hd__intcoder_new(&w->p.intensity, 16, 4);
    rc = rc ? rc : hd__intcoder_new(&w->p.psid, 16, 1);
    rc = rc ? rc : hd__intcoder_new(&w->p.dx, 32, 2);
    rc = rc ? rc : hd__intcoder_new(&w->p.dy, 32, 22);
    rc = rc ? rc : hd__intcoder_new(&w->p.dz, 32, 20);
    for (unsigned i = 1; i < z->n_items && rc == HD_OK; i++) {
        unsigned t = z->items[i].type;
        if (t == IT_GPSTIME11) {
            w->has_g = 1;
            rc = hd__symmodel_new(&w->g.multi, 516);
            rc = rc ? rc : hd__symmodel_new(&w->g.zero, 6);
            rc = rc ? rc : hd__intcoder_new(&w->g.ic, 32, 9);
        } else if (t == IT_RGB12) {
            w->has_c = 1;
            rc = hd__symmodel_new(&w->c.used, 128);
            for (int k = 0; k < 6 && rc == HD_OK; k++) rc = hd__symmodel_new(&w->c.diff[k], 256);
        } else if (t == IT_BYTE) {
            w->has_b = 1;
            w->b.m = calloc(z->items[i].size, sizeof *w->b.m);
            if (!w->b.m) return HD_ENOMEM;
            w->b.n = z->items[i].size;
            for (unsigned k = 0; k < w->b.n && rc == HD_OK; k++) rc = hd__symmodel_new(&w->b.m[k], 256);
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

static uint32_t fold8(int32_t v) { return (uint32_t)v & 255u; }

/* One POINT10 v2 record after the first: updates w->p.last.  0, or -1
 * when a lazily created model could not be allocated. */
static int p10_read(p10_t *p, hd__dec_t *d) {
    unsigned char *L = p->last;
    uint32_t changed = hd__dec_symbol(d, &p->changed);
    unsigned r, n;
    if (changed) {
        if (changed & 32) {
            hd__symmodel_t *m = lazy(&p->bitbyte[L[14]], 256);
            if (!m) return -1;
            L[14] = (unsigned char)hd__dec_symbol(d, m);
        }
        r = L[14] & 7;
        n = (L[14] >> 3) & 7;
        unsigned m = hd__laz_rmap10[n][r];
        if (changed & 16) {
            p->last_int[m] = (uint16_t)hd__ic_decode(&p->intensity, d, p->last_int[m], m < 3 ? m : 3);
        }
        if (changed & 8) {
            hd__symmodel_t *mc = lazy(&p->cls[L[15]], 256);
            if (!mc) return -1;
            L[15] = (unsigned char)hd__dec_symbol(d, mc);
        }
        if (changed & 4) {
            uint32_t v = hd__dec_symbol(d, &p->scan[(L[14] >> 6) & 1]);
            L[16] = (unsigned char)fold8((int32_t)(v + L[16]));
        }
        if (changed & 2) {
            hd__symmodel_t *mu = lazy(&p->user[L[17]], 256);
            if (!mu) return -1;
            L[17] = (unsigned char)hd__dec_symbol(d, mu);
        }
        if (changed & 1) {
            uint16_t ps = hd__ld_u16(L + 18, 0);
            ps = (uint16_t)hd__ic_decode(&p->psid, d, ps, 0);
            L[18] = (unsigned char)ps;
            L[19] = (unsigned char)(ps >> 8);
        }
    } else {
        r = L[14] & 7;
        n = (L[14] >> 3) & 7;
    }
    unsigned m = hd__laz_rmap10[n][r], l = hd__laz_level(n, r);
    int32_t dx = hd__ic_decode(&p->dx, d, p->mx[m].v[2], n == 1);
    hd__median5_add(&p->mx[m], dx);
    int32_t dy = hd__ic_decode(&p->dy, d, p->my[m].v[2], (n == 1) + hd__laz_kctx(p->dx.k, 20));
    hd__median5_add(&p->my[m], dy);
    int32_t X = (int32_t)((uint32_t)i32_at(L) + (uint32_t)dx), Y = (int32_t)((uint32_t)i32_at(L + 4) + (uint32_t)dy);
    int32_t Z = hd__ic_decode(&p->dz, d, p->last_h[l], (n == 1) + hd__laz_kctx((p->dx.k + p->dy.k) / 2, 18));
    p->last_h[l] = Z;
    for (int b = 0; b < 4; b++) {
        L[b] = (unsigned char)((uint32_t)X >> (8 * b));
        L[4 + b] = (unsigned char)((uint32_t)Y >> (8 * b));
        L[8 + b] = (unsigned char)((uint32_t)Z >> (8 * b));
    }
    return 0;
}

/* GPSTIME11 v2: the values only steer which models come next, but they
 * must be followed exactly to stay in step.  A valid stream switches
 * sequence at most once per point; more is an error (returns -1). */
static int gps_read(gps_t *g, hd__dec_t *d) {
    for (int round = 0; round < 4; round++) {
        unsigned L = g->last;
        if (g->diff[L] == 0) {
            uint32_t multi = hd__dec_symbol(d, &g->zero);
            if (multi == 1) {
                g->diff[L] = hd__ic_decode(&g->ic, d, 0, 0);
                g->t[L] = (int64_t)((uint64_t)g->t[L] + (uint64_t)(int64_t)g->diff[L]);
                g->extreme[L] = 0;
            } else if (multi == 2) {
                g->next = (g->next + 1) & 3;
                uint32_t hi = (uint32_t)hd__ic_decode(&g->ic, d, (int32_t)((uint64_t)g->t[L] >> 32), 8);
                uint32_t lo = hd__dec_raw(d, 16);
                lo |= hd__dec_raw(d, 16) << 16;
                g->t[g->next] = (int64_t)((uint64_t)hi << 32 | lo);
                g->last = g->next;
                g->diff[g->last] = 0;
                g->extreme[g->last] = 0;
            } else if (multi > 2) {
                g->last = (L + multi - 2) & 3;
                continue;
            }
            return 0;
        }
        uint32_t multi = hd__dec_symbol(d, &g->multi);
        if (multi == 1) {
            g->t[L] = (int64_t)((uint64_t)g->t[L] + (uint64_t)(int64_t)hd__ic_decode(&g->ic, d, g->diff[L], 1));
            g->extreme[L] = 0;
        } else if (multi < 511) { /* 500 - (-10) + 1: unchanged */
            int32_t diff;
            if (multi == 0) {
                diff = hd__ic_decode(&g->ic, d, 0, 7);
                if (++g->extreme[L] > 3) {
                    g->diff[L] = diff;
                    g->extreme[L] = 0;
                }
            } else if (multi < 500) {
                diff = hd__ic_decode(&g->ic, d, (int32_t)(multi * (uint32_t)g->diff[L]), multi < 10 ? 2 : 3);
            } else if (multi == 500) {
                diff = hd__ic_decode(&g->ic, d, (int32_t)(500u * (uint32_t)g->diff[L]), 4);
                if (++g->extreme[L] > 3) {
                    g->diff[L] = diff;
                    g->extreme[L] = 0;
                }
            } else {
                int32_t mm = 500 - (int32_t)multi;
                if (mm > -10) {
                    diff = hd__ic_decode(&g->ic, d, (int32_t)((uint32_t)mm * (uint32_t)g->diff[L]), 5);
                } else {
                    diff = hd__ic_decode(&g->ic, d, (int32_t)((uint32_t)-10 * (uint32_t)g->diff[L]), 6);
                    if (++g->extreme[L] > 3) {
                        g->diff[L] = diff;
                        g->extreme[L] = 0;
                    }
                }
            }
            g->t[L] = (int64_t)((uint64_t)g->t[L] + (uint64_t)(int64_t)diff);
        } else if (multi == 512) { /* code for a full value */
            g->next = (g->next + 1) & 3;
            uint32_t hi = (uint32_t)hd__ic_decode(&g->ic, d, (int32_t)((uint64_t)g->t[L] >> 32), 8);
            uint32_t lo = hd__dec_raw(d, 16);
            lo |= hd__dec_raw(d, 16) << 16;
            g->t[g->next] = (int64_t)((uint64_t)hi << 32 | lo);
            g->last = g->next;
            g->diff[g->last] = 0;
            g->extreme[g->last] = 0;
        } else if (multi > 512) {
            g->last = (L + multi - 512) & 3;
            continue;
        }
        /* multi == 511: unchanged */
        return 0;
    }
    return -1;
}

static void rgb_read(rgb_t *c, hd__dec_t *d) {
    uint32_t sym = hd__dec_symbol(d, &c->used);
    if (sym & 1) hd__dec_symbol(d, &c->diff[0]);
    if (sym & 2) hd__dec_symbol(d, &c->diff[1]);
    if (sym & 64) {
        if (sym & 4) hd__dec_symbol(d, &c->diff[2]);
        if (sym & 16) hd__dec_symbol(d, &c->diff[4]);
        if (sym & 8) hd__dec_symbol(d, &c->diff[3]);
        if (sym & 32) hd__dec_symbol(d, &c->diff[5]);
    }
}

static void pointwise_chunk(job_t *j, const unsigned char *b, size_t nb, size_t n) {
    laz_t *z = j->z;
    long long at = (long long)z->start[j->chunk];
    if (nb < z->rec) {
        fail(j, HD_EFORMAT, at, "chunk of %zu bytes is shorter than its first point's %zu bytes", nb, z->rec);
        return;
    }
    if (put(j, i32_at(b), i32_at(b + 4), i32_at(b + 8))) return;
    if (n == 1) return;
    pw_t *w = malloc(sizeof *w);
    if (!w) {
        fail(j, HD_ENOMEM, at, "out of memory");
        return;
    }
    if (pw_new(w, z)) {
        fail(j, HD_ENOMEM, at, "out of memory");
        goto done;
    }
    /* initial state from the raw first point */
    for (int i = 0; i < 16; i++) {
        hd__median5_init(&w->p.mx[i]);
        hd__median5_init(&w->p.my[i]);
    }
    memcpy(w->p.last, b, 20);
    w->p.last[12] = w->p.last[13] = 0; /* intensity starts at 0 */
    size_t off = 20;
    for (unsigned i = 1; i < z->n_items; i++) {
        if (z->items[i].type == IT_GPSTIME11) w->g.t[0] = (int64_t)hd__ld_u64(b + off, 0);
        off += z->items[i].size;
    }
    hd__dec_t d;
    hd__dec_init(&d, b + z->rec, nb - z->rec);
    for (size_t i = 1; i < n; i++) {
        if (p10_read(&w->p, &d)) {
            fail(j, HD_ENOMEM, at, "out of memory");
            goto done;
        }
        for (unsigned t = 1; t < z->n_items; t++) {
            unsigned ty = z->items[t].type;
            if (ty == IT_GPSTIME11) {
                if (gps_read(&w->g, &d)) {
                    fail(j, HD_EFORMAT, at, "point %zu: the GPS time switches sequence more than once", j->k);
                    goto done;
                }
            } else if (ty == IT_RGB12) {
                rgb_read(&w->c, &d);
            } else {
                for (unsigned k = 0; k < w->b.n; k++) hd__dec_symbol(&d, &w->b.m[k]);
            }
        }
        if (d.over > 4) break;
        if (put(j, i32_at(w->p.last), i32_at(w->p.last + 4), i32_at(w->p.last + 8))) goto done;
    }
    if (d.over)
        fail(j, HD_EFORMAT, (long long)(z->start[j->chunk] + nb),
             "the chunk's compressed data ends before its %zu points (the decoder ran past the chunk's end)", n);
done:
    pw_free(w);
    free(w);
}

/* ---- POINT14 v3/v4, layered: x and y from layer 0, z from layer 1 -------- */
typedef struct {
    int used;
    hd__symmodel_t changed[8], scanner, rn_same;
    hd__symmodel_t *nret[16], *rnum[16];
    hd__intcoder_t dx, dy, dz;
    hd__median5_t mx[12], my[12];
    int32_t last_z[8];
    int32_t X, Y, Z;
    unsigned r, n, gps_change;
} ctx14_t;

static void ctx14_free(ctx14_t *c) {
    for (int i = 0; i < 8; i++) hd__symmodel_free(&c->changed[i]);
    hd__symmodel_free(&c->scanner);
    hd__symmodel_free(&c->rn_same);
    for (int i = 0; i < 16; i++) {
        if (c->nret[i]) hd__symmodel_free(c->nret[i]);
        if (c->rnum[i]) hd__symmodel_free(c->rnum[i]);
        free(c->nret[i]);
        free(c->rnum[i]);
    }
    hd__intcoder_free(&c->dx);
    hd__intcoder_free(&c->dy);
    hd__intcoder_free(&c->dz);
}

/* Create channel c's models and start it from a point (the chunk's first
 * point, or the previous channel's last). */
static int ctx14_start(ctx14_t *c, const ctx14_t *from) {
    int rc = HD_OK;
    for (int i = 0; i < 8 && rc == HD_OK; i++) rc = hd__symmodel_new(&c->changed[i], 128);
    rc = rc ? rc : hd__symmodel_new(&c->scanner, 3);
    rc = rc ? rc : hd__symmodel_new(&c->rn_same, 13);
    rc = rc ? rc : hd__intcoder_new(&c->dx, 32, 2);
    rc = rc ? rc : hd__intcoder_new(&c->dy, 32, 22);
    rc = rc ? rc : hd__intcoder_new(&c->dz, 32, 20);
    if (rc) return rc;
    for (int i = 0; i < 12; i++) {
        hd__median5_init(&c->mx[i]);
        hd__median5_init(&c->my[i]);
    }
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

static void layered_chunk(job_t *j, const unsigned char *b, size_t nb, size_t n) {
    laz_t *z = j->z;
    long long at = (long long)z->start[j->chunk];
    size_t head = z->rec + 4 + 4 * (size_t)z->n_layers;
    if (nb < head) {
        fail(j, HD_EFORMAT, at, "chunk of %zu bytes is shorter than its first point and layer sizes (%zu bytes)", nb, head);
        return;
    }
    if (put(j, i32_at(b), i32_at(b + 4), i32_at(b + 8))) return;
    uint32_t stored = hd__ld_u32(b + z->rec, 0);
    if (stored != n)
        fail(j, HD_EFORMAT, at + (long long)z->rec, "the chunk says it holds %u points, the chunk table %zu", stored, n);
    uint64_t total = 0;
    for (unsigned i = 0; i < z->n_layers; i++) total += hd__ld_u32(b + z->rec + 4 + 4 * i, 0);
    if (total > nb - head) {
        fail(j, HD_EFORMAT, at + (long long)z->rec + 4, "the chunk's layers need %llu bytes, it has %zu after its header",
             (unsigned long long)total, nb - head);
        return;
    }
    if (j->rc || n == 1) return;
    size_t nxy = hd__ld_u32(b + z->rec + 4, 0), nz = hd__ld_u32(b + z->rec + 8, 0);
    const unsigned char *lxy = b + head, *lz = lxy + nxy;
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
    hd__dec_t dxy, dz;
    hd__dec_init(&dxy, lxy, nxy);
    hd__dec_init(&dz, lz, nz);
    dz.over = 0; /* an empty z layer (z constant in the chunk) is never read */
    if (ctx14_start(&cx[cur], &first)) {
        fail(j, HD_ENOMEM, at, "out of memory");
        goto done;
    }
    for (size_t i = 1; i < n; i++) {
        ctx14_t *c = &cx[cur];
        unsigned lpr = (c->r == 1) + 2 * (c->r >= c->n) + 4 * c->gps_change;
        uint32_t changed = hd__dec_symbol(&dxy, &c->changed[lpr]);
        if (changed & 64) {
            unsigned next = (cur + hd__dec_symbol(&dxy, &c->scanner) + 1) & 3;
            if (!cx[next].used && ctx14_start(&cx[next], c)) {
                fail(j, HD_ENOMEM, at, "out of memory");
                goto done;
            }
            cur = next;
            c = &cx[cur];
        }
        unsigned gps = (changed >> 4) & 1;
        unsigned last_n = c->n, last_r = c->r, nn = last_n, r = last_r;
        if (changed & 4) {
            hd__symmodel_t *m = lazy(&c->nret[last_n], 16);
            if (!m) {
                fail(j, HD_ENOMEM, at, "out of memory");
                goto done;
            }
            nn = hd__dec_symbol(&dxy, m);
        }
        switch (changed & 3) {
        case 1: r = (last_r + 1) & 15; break;
        case 2: r = (last_r + 15) & 15; break;
        case 3:
            if (gps) {
                hd__symmodel_t *m = lazy(&c->rnum[last_r], 16);
                if (!m) {
                    fail(j, HD_ENOMEM, at, "out of memory");
                    goto done;
                }
                r = hd__dec_symbol(&dxy, m);
            } else {
                r = (last_r + hd__dec_symbol(&dxy, &c->rn_same) + 2) & 15;
            }
            break;
        default: break;
        }
        c->n = nn;
        c->r = r;
        unsigned m = hd__laz_rmap14[nn][r], l = hd__laz_level(nn, r), mi = m << 1 | gps;
        int32_t dx = hd__ic_decode(&c->dx, &dxy, c->mx[mi].v[2], nn == 1);
        c->X = (int32_t)((uint32_t)c->X + (uint32_t)dx);
        hd__median5_add(&c->mx[mi], dx);
        int32_t dy = hd__ic_decode(&c->dy, &dxy, c->my[mi].v[2], (nn == 1) + hd__laz_kctx(c->dx.k, 20));
        c->Y = (int32_t)((uint32_t)c->Y + (uint32_t)dy);
        hd__median5_add(&c->my[mi], dy);
        if (nz) {
            c->Z = hd__ic_decode(&c->dz, &dz, c->last_z[l], (nn == 1) + hd__laz_kctx((c->dx.k + c->dy.k) / 2, 18));
            c->last_z[l] = c->Z;
        }
        c->gps_change = gps;
        if (dxy.over > 4 || dz.over > 4) break;
        if (put(j, c->X, c->Y, c->Z)) goto done;
    }
    if (dxy.over || dz.over)
        fail(j, HD_EFORMAT, at + (long long)head + (long long)(dxy.over ? 0 : nxy),
             "the chunk's %s layer ends before its %zu points (the decoder ran past the layer's end)",
             dxy.over ? "x/y" : "z", n);
done:
    for (int c = 0; c < 4; c++) ctx14_free(&cx[c]);
    free(cx);
}

static void decode_chunk(void *ctx, size_t task, int worker) {
    (void)worker;
    laz_t *z = ctx;
    job_t j = {z, task, z->r->sink, z->r->sink->dtype == HD_FLOAT32 ? (double)FLT_MAX : HD_MAX_COORD,
               (size_t)z->first[task], 0, -1, ""};
    const unsigned char *b = z->d + z->start[task];
    size_t nb = (size_t)(z->start[task + 1] - z->start[task]), n = (size_t)(z->first[task + 1] - z->first[task]);
    if (z->layered) layered_chunk(&j, b, nb, n);
    else pointwise_chunk(&j, b, nb, n);
    z->rc[task] = j.rc;
    z->at[task] = j.at;
    memcpy(z->msg[task], j.msg, sizeof j.msg);
}

/* ---- the VLR, the chunk table ----------------------------------------------- */
static int find_vlr(laz_t *z, const hd__las_header_t *h, const unsigned char **vlr, size_t *len, size_t *vlr_at) {
    hd__read_t *r = z->r;
    size_t p = h->header;
    for (uint32_t i = 0; i < h->n_vlr; i++) {
        if (p + 54 > h->offset)
            return hd__io_err_at(r, HD_EFORMAT, (long long)p, "VLR %u of %u does not fit before the point data at byte %zu", i + 1,
                                 h->n_vlr, h->offset);
        size_t n = hd__ld_u16(z->d + p + 20, 0);
        if (p + 54 + n > h->offset)
            return hd__io_err_at(r, HD_EFORMAT, (long long)p + 20, "VLR %u's %zu bytes run past the point data at byte %zu", i + 1,
                                 n, h->offset);
        if (memcmp(z->d + p + 2, "laszip encoded", 14) == 0 && z->d[p + 16] == 0 && hd__ld_u16(z->d + p + 18, 0) == 22204) {
            *vlr = z->d + p + 54;
            *len = n;
            *vlr_at = p + 54;
            return HD_OK;
        }
        p += 54 + n;
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
    if (compressor != 2 && compressor != 3)
        return hd__io_err_at(r, HD_EUNSUPPORTED, (long long)at,
                             "LASzip compressor %u (%s); the chunked pointwise (2) and layered (3) compressors are read",
                             compressor, compressor == 1 ? "pointwise without chunks, from LASzip before 2.0" : "unknown");
    z->layered = compressor == 3;
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
                 it->version == 2;
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
                                            : "POINT10 first, then GPSTIME11, RGB12, BYTE (version 2)");
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
        else if (pts > (uint64_t)bytes * HD__LAZ_POINTS_PER_BYTE)
            rc = hd__io_err_at(r, HD_EFORMAT, (long long)z->start[i], "chunk %u of %u claims %u points in %u bytes (at most %d per byte)",
                               i + 1, nc, pts, bytes, HD__LAZ_POINTS_PER_BYTE);
    }
    hd__intcoder_free(&ic);
    if (rc == HD_OK && z->first[nc] != count)
        rc = hd__io_err_at(r, HD_EFORMAT, (long long)t + 8, "the chunks hold %llu points, the header says %llu",
                           (unsigned long long)z->first[nc], (unsigned long long)count);
    return rc;
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
    uint32_t chunk_size = 0;
    int rc = parse_vlr(&z, h, &chunk_size);
    if (rc == HD_OK && h->count == 0) return HD_OK;
    if (rc == HD_OK) rc = read_table(&z, h, chunk_size);
    if (rc == HD_OK && r->sink->count != 0) rc = hd__io_err(r, HD_EINVAL, "internal: LAZ points into a non-empty sink");
    if (rc == HD_OK && (rc = hd__sink_reserve(r->sink, (size_t)h->count)) != HD_OK)
        rc = hd__io_err(r, rc, "cannot allocate %llu points: %s", (unsigned long long)h->count, hd_strerror(rc));
    if (rc == HD_OK) {
        z.rc = hd__malloc_array(z.n_chunks, sizeof *z.rc);
        z.at = hd__malloc_array(z.n_chunks, sizeof *z.at);
        z.msg = hd__malloc_array(z.n_chunks, sizeof *z.msg);
        if (!z.rc || !z.at || !z.msg) rc = hd__io_err(r, HD_ENOMEM, "out of memory");
    }
    if (rc == HD_OK) {
        hd__parallel_for(hd__thread_count(r->threads, z.n_chunks), z.n_chunks, decode_chunk, &z);
        for (size_t c = 0; c < z.n_chunks && rc == HD_OK; c++)
            if (z.rc[c]) rc = hd__io_err_at(r, z.rc[c], z.at[c], "chunk %zu of %zu: %s", c + 1, z.n_chunks, z.msg[c]);
        if (rc == HD_OK) r->sink->count = (size_t)h->count;
    }
    free(z.start);
    free(z.first);
    free(z.rc);
    free(z.at);
    free(z.msg);
    return rc;
}
