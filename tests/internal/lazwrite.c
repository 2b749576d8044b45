/*
 * lazwrite.c -- the tests' LAZ writer (lazwrite.h), over the library's
 * range encoder (src/io/lazcoder.h).
 */
#include "lazwrite.h"

#include "io/lasfield.h"
#include "io/laz14.h"
#include "io/lazcoder.h"

#include <assert.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

lazw_layout_t lazw_last;

/* The library's encoder (src/io/lazcoder.c), its output a tf_buf_t's
 * bytes. */
typedef hd__enc_t enc_t;
#define enc_init hd__enc_init
#define enc_symbol hd__enc_symbol
#define enc_done hd__enc_done
#define ic_encode hd__ic_encode

static void symnew(hd__symmodel_t *m, uint32_t n) {
    if (hd__symmodel_new(m, n)) abort();
}
static void icnew(hd__intcoder_t *ic, uint32_t bits, uint32_t ctx) {
    if (hd__intcoder_new(ic, bits, ctx)) abort();
}

/* ---- POINT10 v2 chunks --------------------------------------------------- */
static size_t rec_size(const lazw_opts_t *o) {
    static const size_t base[7] = {20, 28, 26, 34, 0, 0, 30};
    return base[o->format] + o->extra;
}

static void raw_point(tf_buf_t *b, const lazw_opts_t *o, const lazw_point_t *p) {
    tf_u32(b, (uint32_t)p->x, 0);
    tf_u32(b, (uint32_t)p->y, 0);
    tf_u32(b, (uint32_t)p->z, 0);
    tf_u16(b, 0, 0); /* intensity */
    if (o->format < 6) {
        tf_u8(b, (unsigned)(p->r | p->n << 3));
        tf_u8(b, 2);             /* classification */
        tf_u8(b, 0);             /* scan angle */
        tf_u8(b, 7);             /* user data */
        tf_u16(b, 11, 0);        /* point source */
        if (o->format == 1 || o->format == 3) tf_f64(b, 123456.5, 0);
        if (o->format >= 2) tf_u16(b, 100, 0), tf_u16(b, 200, 0), tf_u16(b, 300, 0);
    } else {
        tf_u8(b, (unsigned)(p->r | p->n << 4));
        tf_u8(b, (unsigned)(p->channel << 4));
        tf_u8(b, 2);      /* classification */
        tf_u8(b, 7);      /* user data */
        tf_u16(b, 0, 0);  /* scan angle */
        tf_u16(b, 11, 0); /* point source */
        tf_f64(b, 123456.5, 0);
    }
    for (unsigned i = 0; i < o->extra; i++) tf_u8(b, 40 + i);
}

static void chunk10(tf_buf_t *b, const lazw_opts_t *o, const lazw_point_t *p, size_t n) {
    raw_point(b, o, p);
    enc_t e;
    enc_init(&e);
    hd__symmodel_t changed, bitbyte[256];
    hd__intcoder_t dx, dy, dz;
    symnew(&changed, 64);
    icnew(&dx, 32, 2);
    icnew(&dy, 32, 22);
    icnew(&dz, 32, 20);
    char made[256] = {0};
    hd__symmodel_t gzero, rgbused, *bytes = calloc(o->extra ? o->extra : 1, sizeof *bytes);
    assert(bytes);
    symnew(&gzero, 6);
    symnew(&rgbused, 128);
    for (unsigned i = 0; i < o->extra; i++) symnew(&bytes[i], 256);
    hd__median5_t mx[16], my[16];
    for (int i = 0; i < 16; i++) hd__median5_init(&mx[i]), hd__median5_init(&my[i]);
    int32_t last_h[8] = {0}, X = p[0].x, Y = p[0].y;
    unsigned byte14 = (unsigned)(p[0].r | p[0].n << 3);
    for (size_t i = 1; i < n; i++) {
        unsigned nb = (unsigned)(p[i].r | p[i].n << 3);
        enc_symbol(&e, &changed, nb != byte14 ? 32 : 0);
        if (nb != byte14) {
            if (!made[byte14]) symnew(&bitbyte[byte14], 256), made[byte14] = 1;
            enc_symbol(&e, &bitbyte[byte14], nb);
            byte14 = nb;
        }
        unsigned r = p[i].r, nn = p[i].n, m = hd__laz_rmap10[nn][r], l = hd__laz_level(nn, r);
        int32_t ddx = (int32_t)((uint32_t)p[i].x - (uint32_t)X), ddy = (int32_t)((uint32_t)p[i].y - (uint32_t)Y);
        ic_encode(&dx, &e, mx[m].v[2], ddx, nn == 1);
        hd__median5_add(&mx[m], ddx);
        ic_encode(&dy, &e, my[m].v[2], ddy, (nn == 1) + hd__laz_kctx(dx.k, 20));
        hd__median5_add(&my[m], ddy);
        ic_encode(&dz, &e, last_h[l], p[i].z, (nn == 1) + hd__laz_kctx((dx.k + dy.k) / 2, 18));
        last_h[l] = p[i].z;
        X = p[i].x;
        Y = p[i].y;
        if (o->format == 1 || o->format == 3) enc_symbol(&e, &gzero, 0); /* GPS time unchanged */
        if (o->format >= 2) enc_symbol(&e, &rgbused, 0);                 /* colour unchanged */
        for (unsigned k = 0; k < o->extra; k++) enc_symbol(&e, &bytes[k], 0);
    }
    enc_done(&e);
    tf_put(b, e.buf, e.size);
    hd__enc_free(&e);
    hd__symmodel_free(&changed);
    hd__symmodel_free(&gzero);
    hd__symmodel_free(&rgbused);
    for (unsigned i = 0; i < o->extra; i++) hd__symmodel_free(&bytes[i]);
    free(bytes);
    for (int i = 0; i < 256; i++)
        if (made[i]) hd__symmodel_free(&bitbyte[i]);
    hd__intcoder_free(&dx);
    hd__intcoder_free(&dy);
    hd__intcoder_free(&dz);
}

/* POINT10 v1 (LASzip 1.x): x, y, z predicted by the median of the last
 * three differences, then the changed-values symbol; the other items v1
 * (their fields unchanged). */
static int32_t median3(const int32_t v[3]) {
    if (v[0] < v[1]) return v[1] < v[2] ? v[1] : v[0] < v[2] ? v[2] : v[0];
    return v[0] < v[2] ? v[0] : v[1] < v[2] ? v[2] : v[1];
}
static void chunk10v1(tf_buf_t *b, const lazw_opts_t *o, const lazw_point_t *p, size_t n) {
    raw_point(b, o, p);
    enc_t e;
    enc_init(&e);
    hd__symmodel_t changed, bitbyte[256], gzero, rgbused;
    hd__intcoder_t dx, dy, dz, bic;
    symnew(&changed, 64);
    symnew(&gzero, 3);
    symnew(&rgbused, 64);
    icnew(&dx, 32, 1);
    icnew(&dy, 32, 20);
    icnew(&dz, 32, 20);
    icnew(&bic, 8, o->extra ? o->extra : 1);
    char made[256] = {0};
    int32_t diff[2][3] = {{0}}, X = p[0].x, Y = p[0].y, Z = p[0].z;
    unsigned incr = 0, byte14 = (unsigned)(p[0].r | p[0].n << 3);
    for (size_t i = 1; i < n; i++) {
        int32_t ddx = (int32_t)((uint32_t)p[i].x - (uint32_t)X), ddy = (int32_t)((uint32_t)p[i].y - (uint32_t)Y);
        ic_encode(&dx, &e, median3(diff[0]), ddx, 0);
        unsigned k = dx.k;
        ic_encode(&dy, &e, median3(diff[1]), ddy, k < 19 ? k : 19);
        k = (k + dy.k) / 2;
        ic_encode(&dz, &e, Z, p[i].z, k < 19 ? k : 19);
        unsigned nb = (unsigned)(p[i].r | p[i].n << 3);
        enc_symbol(&e, &changed, nb != byte14 ? 16 : 0);
        if (nb != byte14) {
            if (!made[byte14]) symnew(&bitbyte[byte14], 256), made[byte14] = 1;
            enc_symbol(&e, &bitbyte[byte14], nb);
            byte14 = nb;
        }
        diff[0][incr] = ddx;
        diff[1][incr] = ddy;
        incr = (incr + 1) % 3;
        X = p[i].x, Y = p[i].y, Z = p[i].z;
        if (o->format == 1 || o->format == 3) enc_symbol(&e, &gzero, 0);
        if (o->format >= 2) enc_symbol(&e, &rgbused, 0);
        for (unsigned q = 0; q < o->extra; q++) ic_encode(&bic, &e, 40 + q, 40 + q, q);
    }
    enc_done(&e);
    tf_put(b, e.buf, e.size);
    hd__enc_free(&e);
    hd__symmodel_t *ms[] = {&changed, &gzero, &rgbused};
    for (int i = 0; i < 3; i++) hd__symmodel_free(ms[i]);
    for (int i = 0; i < 256; i++)
        if (made[i]) hd__symmodel_free(&bitbyte[i]);
    hd__intcoder_t *ics[] = {&dx, &dy, &dz, &bic};
    hd__intcoders_free(ics, 4);
}

/* ---- POINT14 v3 layered chunks -------------------------------------------- */
typedef struct {
    int used;
    hd__symmodel_t changed[8], scanner, rn_same, nret[16];
    char nret_made[16];
    hd__intcoder_t dx, dy, dz;
    hd__median5_t mx[12], my[12];
    int32_t last_z[8], X, Y, Z;
    unsigned r, n;
} c14_t;

static void c14_start(c14_t *c, const c14_t *from) {
    memset(c, 0, sizeof *c);
    for (int i = 0; i < 8; i++) symnew(&c->changed[i], 128);
    symnew(&c->scanner, 3);
    symnew(&c->rn_same, 13);
    icnew(&c->dx, 32, 2);
    icnew(&c->dy, 32, 22);
    icnew(&c->dz, 32, 20);
    for (int i = 0; i < 12; i++) hd__median5_init(&c->mx[i]), hd__median5_init(&c->my[i]);
    c->X = from->X, c->Y = from->Y, c->Z = from->Z, c->r = from->r, c->n = from->n;
    for (int i = 0; i < 8; i++) c->last_z[i] = from->Z;
    c->used = 1;
}
static void c14_free(c14_t *c) {
    if (!c->used) return;
    for (int i = 0; i < 8; i++) hd__symmodel_free(&c->changed[i]);
    hd__symmodel_free(&c->scanner);
    hd__symmodel_free(&c->rn_same);
    for (int i = 0; i < 16; i++)
        if (c->nret_made[i]) hd__symmodel_free(&c->nret[i]);
    hd__intcoder_free(&c->dx);
    hd__intcoder_free(&c->dy);
    hd__intcoder_free(&c->dz);
}

static void chunk14(tf_buf_t *b, const lazw_opts_t *o, const lazw_point_t *p, size_t n) {
    raw_point(b, o, p);
    tf_u32(b, (uint32_t)n, 0);
    enc_t exy, ez;
    enc_init(&exy);
    enc_init(&ez);
    int zchanges = 0;
    for (size_t i = 1; i < n; i++) zchanges |= p[i].z != p[0].z;
    c14_t *cx = calloc(4, sizeof *cx), first = {0};
    first.X = p[0].x, first.Y = p[0].y, first.Z = p[0].z, first.r = p[0].r, first.n = p[0].n;
    unsigned cur = p[0].channel;
    c14_start(&cx[cur], &first);
    for (size_t i = 1; i < n; i++) {
        c14_t *c = &cx[cur];
        unsigned lpr = (c->r == 1) + 2 * (c->r >= c->n); /* the GPS time never changes */
        unsigned ch = p[i].channel;
        c14_t *t = ch != cur && cx[ch].used ? &cx[ch] : c;
        unsigned diff = (p[i].r - t->r) & 15, changed = 0;
        if (ch != cur) changed |= 64;
        if (p[i].n != t->n) changed |= 4;
        changed |= diff == 0 ? 0 : diff == 1 ? 1 : diff == 15 ? 2 : 3;
        enc_symbol(&exy, &c->changed[lpr], changed);
        if (ch != cur) {
            enc_symbol(&exy, &c->scanner, (ch - cur - 1) & 3);
            if (!cx[ch].used) c14_start(&cx[ch], c);
            cur = ch;
            c = &cx[cur];
        }
        if (changed & 4) {
            if (!c->nret_made[c->n]) symnew(&c->nret[c->n], 16), c->nret_made[c->n] = 1;
            enc_symbol(&exy, &c->nret[c->n], p[i].n);
        }
        if ((changed & 3) == 3) enc_symbol(&exy, &c->rn_same, diff - 2);
        c->n = p[i].n;
        c->r = p[i].r;
        unsigned nn = c->n, mi = hd__laz_rmap14[nn][c->r] << 1, l = hd__laz_level(nn, c->r);
        int32_t ddx = (int32_t)((uint32_t)p[i].x - (uint32_t)c->X), ddy = (int32_t)((uint32_t)p[i].y - (uint32_t)c->Y);
        ic_encode(&c->dx, &exy, c->mx[mi].v[2], ddx, nn == 1);
        hd__median5_add(&c->mx[mi], ddx);
        ic_encode(&c->dy, &exy, c->my[mi].v[2], ddy, (nn == 1) + hd__laz_kctx(c->dx.k, 20));
        hd__median5_add(&c->my[mi], ddy);
        c->X = p[i].x;
        c->Y = p[i].y;
        if (zchanges) {
            ic_encode(&c->dz, &ez, c->last_z[l], p[i].z, (nn == 1) + hd__laz_kctx((c->dx.k + c->dy.k) / 2, 18));
            c->last_z[l] = p[i].z;
        }
        c->Z = p[i].z;
    }
    enc_done(&exy);
    if (zchanges) enc_done(&ez);
    tf_u32(b, (uint32_t)exy.size, 0);
    tf_u32(b, (uint32_t)ez.size, 0);
    for (unsigned i = 2; i < 9 + o->extra; i++) tf_u32(b, 0, 0); /* unchanged layers: empty */
    tf_put(b, exy.buf, exy.size);
    tf_put(b, ez.buf, ez.size);
    hd__enc_free(&exy);
    hd__enc_free(&ez);
    for (int i = 0; i < 4; i++) c14_free(&cx[i]);
    free(cx);
}

void lazw_table(tf_buf_t *out, const uint32_t *counts, const uint32_t *bytes, size_t nc) {
    tf_u32(out, 0, 0);
    tf_u32(out, (uint32_t)nc, 0);
    enc_t e;
    enc_init(&e);
    hd__intcoder_t ic;
    icnew(&ic, 32, 2);
    for (size_t c = 0; c < nc; c++) {
        if (counts) ic_encode(&ic, &e, c ? (int32_t)counts[c - 1] : 0, (int32_t)counts[c], 0);
        ic_encode(&ic, &e, c ? (int32_t)bytes[c - 1] : 0, (int32_t)bytes[c], 1);
    }
    enc_done(&e);
    tf_put(out, e.buf, e.size);
    hd__enc_free(&e);
    hd__intcoder_free(&ic);
}

/* ---- the file --------------------------------------------------------------- */
void lazw_encode(tf_buf_t *out, const lazw_opts_t *o, const lazw_point_t *p, size_t n) {
    int layered = o->format >= 6;
    size_t header = layered ? 375 : 227, rec = rec_size(o);
    unsigned n_items = 1 + (o->format == 1 || o->format == 3) + (o->format == 2 || o->format == 3) + (o->extra > 0);
    if (layered) n_items = 1 + (o->extra > 0);
    size_t vlr = 34 + 6 * n_items, offset = header + 54 + vlr, base = out->size;
    /* header */
    tf_put(out, "LASF", 4);
    for (int i = 4; i < 24; i++) tf_u8(out, 0);
    tf_u8(out, 1);
    tf_u8(out, layered ? 4 : 2);
    while (out->size - base < 94) tf_u8(out, 0);
    tf_u16(out, (unsigned)header, 0);
    tf_u32(out, (uint32_t)offset, 0);
    tf_u32(out, 1, 0); /* VLRs */
    tf_u8(out, (unsigned)o->format | 0x80);
    tf_u16(out, (unsigned)rec, 0);
    tf_u32(out, layered || n > 0xFFFFFFFFu ? 0 : (uint32_t)n, 0);
    while (out->size - base < 131) tf_u8(out, 0);
    for (int c = 0; c < 3; c++) tf_f64(out, o->scale[c], 0);
    for (int c = 0; c < 3; c++) tf_f64(out, o->offset[c], 0);
    while (out->size - base < (layered ? 247 : header)) tf_u8(out, 0);
    if (layered) {
        tf_u64(out, n, 0);
        while (out->size - base < header) tf_u8(out, 0);
    }
    /* VLR */
    tf_u16(out, 0, 0);
    char user[16] = "laszip encoded", desc[32] = "lazwrite (tests)";
    tf_put(out, user, 16);
    tf_u16(out, 22204, 0);
    tf_u16(out, (unsigned)vlr, 0);
    tf_put(out, desc, 32);
    lazw_last.vlr = out->size - base;
    unsigned iv = o->v1 ? 1 : 2;
    tf_u16(out, layered ? 3 : o->v1 ? 1 : 2, 0);
    tf_u16(out, 0, 0);
    tf_u8(out, layered ? 3 : iv);
    tf_u8(out, layered ? 4 : 2);
    tf_u16(out, 0, 0);
    tf_u32(out, 0, 0);
    tf_u32(out, o->chunk_size ? o->chunk_size : 0xFFFFFFFFu, 0);
    tf_u64(out, (uint64_t)-1, 0);
    tf_u64(out, (uint64_t)-1, 0);
    tf_u16(out, n_items, 0);
    if (layered) {
        tf_u16(out, 10, 0), tf_u16(out, 30, 0), tf_u16(out, 3, 0);
        if (o->extra) tf_u16(out, 14, 0), tf_u16(out, o->extra, 0), tf_u16(out, 3, 0);
    } else {
        tf_u16(out, 6, 0), tf_u16(out, 20, 0), tf_u16(out, iv, 0);
        if (o->format == 1 || o->format == 3) tf_u16(out, 7, 0), tf_u16(out, 8, 0), tf_u16(out, iv, 0);
        if (o->format >= 2) tf_u16(out, 8, 0), tf_u16(out, 6, 0), tf_u16(out, iv, 0);
        if (o->extra) tf_u16(out, 0, 0), tf_u16(out, o->extra, 0), tf_u16(out, iv, 0);
    }
    assert(out->size - base == offset);
    if (o->v1) { /* LASzip 1.x: one stream, no chunk table */
        lazw_last.points = lazw_last.chunk[0] = offset;
        lazw_last.table = 0;
        if (n) chunk10v1(out, o, p, n);
        return;
    }
    /* chunks */
    lazw_last.points = offset;
    size_t table_ptr = out->size;
    tf_u64(out, 0, 0);
    size_t nc = o->chunk_size ? (n + o->chunk_size - 1) / o->chunk_size : o->n_chunks;
    uint32_t *cnt = calloc(nc + 1, sizeof *cnt), *bytes = calloc(nc + 1, sizeof *bytes);
    size_t done = 0;
    for (size_t c = 0; c < nc; c++) {
        size_t k = o->chunk_size ? (n - done < o->chunk_size ? n - done : o->chunk_size) : o->chunks[c];
        size_t at = out->size;
        if (c < 64) lazw_last.chunk[c] = at - base;
        if (layered) chunk14(out, o, p + done, k);
        else chunk10(out, o, p + done, k);
        cnt[c] = (uint32_t)k;
        bytes[c] = (uint32_t)(out->size - at);
        done += k;
    }
    assert(done == n);
    /* the chunk table */
    uint64_t tab = out->size - base;
    lazw_last.table = (size_t)tab;
    for (int i = 0; i < 8; i++) out->data[table_ptr + i] = (unsigned char)(tab >> (8 * i));
    lazw_table(out, o->chunk_size ? NULL : cnt, bytes, nc);
    free(cnt);
    free(bytes);
}

void lazw_random(gen_rng_t *g, lazw_point_t *p, size_t n, int format) {
    int32_t x = (int32_t)gen_u64(g), y = (int32_t)gen_u64(g), z = (int32_t)(gen_u64(g) % 100000);
    unsigned maxn = format >= 6 ? 15 : 7, ch = 0;
    for (size_t i = 0; i < n; i++) {
        uint64_t u = gen_u64(g);
        /* mostly small steps, sometimes any 32-bit jump (k up to 32) */
        switch (u % 8) {
        case 0: x = (int32_t)gen_u64(g), y = (int32_t)gen_u64(g), z = (int32_t)gen_u64(g); break;
        case 1: break; /* a repeated point */
        default:
            x = (int32_t)((uint32_t)x + (uint32_t)(gen_u64(g) % 2001) - 1000u);
            y = (int32_t)((uint32_t)y + (uint32_t)(gen_u64(g) % 201) - 100u);
            z = (int32_t)((uint32_t)z + (uint32_t)(gen_u64(g) % 21) - 10u);
        }
        unsigned nn = (unsigned)(u >> 8) % 4 ? 1 + (unsigned)(u >> 16) % 4 : (unsigned)(u >> 16) % (maxn + 1);
        unsigned r = (unsigned)(u >> 24) % 8 ? 1 + (unsigned)(u >> 28) % (nn ? nn : 1) : (unsigned)(u >> 32) % (maxn + 1);
        if (format >= 6 && (u >> 40) % 16 == 0) ch = (unsigned)(u >> 44) % 4;
        p[i] = (lazw_point_t){x, y, z, (unsigned char)r, (unsigned char)nn, (unsigned char)ch};
    }
}

/* ---- pointwise files of whole records (the library's encoder) ------------ */
/* n random records of point format fmt (0-3) with `extra` extra bytes:
 * every field varies (returns, flags, classification, scan angle, user
 * data, point source, intensity, GPS times repeated, stepping and jumping,
 * colours grey and not, extra bytes). */
unsigned char *lazw_rich_records(gen_rng_t *g, int fmt, unsigned extra, size_t n, size_t *rec) {
    static const unsigned base[4] = {20, 28, 26, 34};
    *rec = base[fmt] + extra;
    unsigned char *r = calloc(n, *rec);
    int32_t x = 0, y = 0, z = 0;
    uint64_t t = 0x41C0000000000000ull;
    uint16_t rgb[3] = {100, 200, 300};
    for (size_t k = 0; k < n; k++) {
        unsigned char *p = r + k * *rec;
        uint64_t u = gen_u64(g);
        x += (int32_t)(u % 2001) - 1000, y += (int32_t)(u >> 16 & 255) - 128, z += (int32_t)(u >> 24 & 15) - 7;
        if (u % 97 == 0) x = (int32_t)gen_u64(g);
        for (int b = 0; b < 4; b++) p[b] = (unsigned char)(x >> 8 * b), p[4 + b] = (unsigned char)(y >> 8 * b), p[8 + b] = (unsigned char)(z >> 8 * b);
        unsigned nr = 1 + (unsigned)(u >> 32) % 5, ret = 1 + (unsigned)(u >> 36) % nr;
        uint16_t inten = (uint16_t)(u >> 40 & 7 ? 500 + (u >> 44 & 63) : u >> 48);
        p[12] = (unsigned char)inten, p[13] = (unsigned char)(inten >> 8);
        p[14] = (unsigned char)(ret | nr << 3 | (u >> 50 & 3) << 6);
        p[15] = (unsigned char)(u >> 52 & 3 ? 2 : u >> 54 & 31);
        p[16] = (unsigned char)(u >> 56 & 1 ? (int8_t)(u >> 57 & 63) - 30 : 0);
        p[17] = (unsigned char)(u >> 59 & 1 ? 7 : u >> 40);
        p[18] = (unsigned char)(u >> 61 & 1 ? 11 : u >> 20), p[19] = 0;
        size_t off = 20;
        if (fmt == 1 || fmt == 3) {
            uint64_t w = gen_u64(g);
            t = w % 4 == 0 ? t : w % 4 == 1 ? t + 1000 : w % 4 == 2 ? t + (w >> 8 & 0xFFFFF) : w % 16 == 3 ? t + (w << 30) : t - 5;
            for (int b = 0; b < 8; b++) p[off + b] = (unsigned char)(t >> 8 * b);
            off += 8;
        }
        if (fmt >= 2) {
            uint64_t w = gen_u64(g);
            if (w % 3 == 0) rgb[0] = rgb[1] = rgb[2] = (uint16_t)(w >> 8); /* grey */
            else if (w % 3 == 1) rgb[0] = (uint16_t)(rgb[0] + (w >> 8 & 15)), rgb[2] = (uint16_t)(w >> 24);
            for (int c = 0; c < 3; c++) p[off + 2 * c] = (unsigned char)rgb[c], p[off + 2 * c + 1] = (unsigned char)(rgb[c] >> 8);
            off += 6;
        }
        for (unsigned e = 0; e < extra; e++) p[off + e] = (unsigned char)(k % 7 ? 40 + e : gen_u64(g));
    }
    return r;
}

/* A LAZ file of the n records (rec bytes each, point format fmt) in chunks
 * of `chunk` points: LAS 1.2 with the LASzip VLR of compressor 2, each
 * chunk compressed by the library's pointwise encoder, or (layered) LAS 1.4
 * with compressor 3 and the layered encoder; the items `it`; the chunk
 * table last. */
static void laz_file(tf_buf_t *b, int fmt, const hd__laz14_items_t *it, const unsigned char *recs, size_t rec,
                     size_t n, size_t chunk, int layered) {
    size_t header = layered ? 375 : 227, vlr = 34 + 6 * it->n, offset = header + 54 + vlr;
    tf_put(b, "LASF", 4);
    while (b->size < 24) tf_u8(b, 0);
    tf_u8(b, 1), tf_u8(b, layered ? 4 : 2);
    while (b->size < 94) tf_u8(b, 0);
    tf_u16(b, (unsigned)header, 0), tf_u32(b, (uint32_t)offset, 0), tf_u32(b, 1, 0);
    tf_u8(b, (unsigned)fmt | 0x80), tf_u16(b, (unsigned)rec, 0), tf_u32(b, layered ? 0 : (uint32_t)n, 0);
    while (b->size < 131) tf_u8(b, 0);
    for (int c = 0; c < 3; c++) tf_f64(b, 0.01, 0);
    for (int c = 0; c < 3; c++) tf_f64(b, 0, 0);
    if (layered) {
        while (b->size < 247) tf_u8(b, 0);
        tf_u64(b, n, 0);
    }
    while (b->size < header) tf_u8(b, 0);
    char user[16] = "laszip encoded", desc[32] = "";
    tf_u16(b, 0, 0), tf_put(b, user, 16), tf_u16(b, 22204, 0), tf_u16(b, (unsigned)vlr, 0), tf_put(b, desc, 32);
    unsigned compressor = layered ? 3 : 2;
    tf_u16(b, compressor, 0), tf_u16(b, 0, 0), tf_u8(b, compressor), tf_u8(b, layered ? 4 : 2), tf_u16(b, 0, 0), tf_u32(b, 0, 0);
    tf_u32(b, (uint32_t)chunk, 0), tf_u64(b, (uint64_t)-1, 0), tf_u64(b, (uint64_t)-1, 0), tf_u16(b, it->n, 0);
    for (unsigned i = 0; i < it->n; i++) tf_u16(b, it->type[i], 0), tf_u16(b, it->size[i], 0), tf_u16(b, it->version[i], 0);
    size_t ptr = b->size, nc = (n + chunk - 1) / chunk;
    tf_u64(b, 0, 0);
    uint64_t *bytes = calloc(nc + 1, sizeof *bytes);
    hd__enc_t e;
    hd__enc_init(&e);
    for (size_t c = 0; c < nc; c++) {
        size_t k = n - c * chunk < chunk ? n - c * chunk : chunk;
        const unsigned char *first = recs + c * chunk * rec;
        if (layered ? hd__laz14_encode(first, k, rec, it, &e)
                    : hd__laz_encode_pointwise(first, k, rec, it->type, it->size, it->n, &e))
            abort();
        if (c < 64) lazw_last.chunk[c] = b->size;
        tf_put(b, first, rec);
        tf_put(b, e.buf, e.size);
        bytes[c] = rec + e.size;
    }
    uint64_t tab = b->size;
    lazw_last.vlr = header + 54, lazw_last.points = offset, lazw_last.table = (size_t)tab;
    for (int i = 0; i < 8; i++) b->data[ptr + i] = (unsigned char)(tab >> 8 * i);
    tf_u32(b, 0, 0), tf_u32(b, (uint32_t)nc, 0);
    if (hd__laz_table_encode(0, nc, NULL, bytes, &e)) abort();
    tf_put(b, e.buf, e.size);
    hd__enc_free(&e);
    free(bytes);
}

/* One more item of the file's list. */
static void add_item(hd__laz14_items_t *it, unsigned type, unsigned size, unsigned version) {
    it->type[it->n] = type, it->size[it->n] = size, it->version[it->n++] = version;
}

/* A pointwise LAZ file (LAS 1.2, chunks of `chunk` points) of the records,
 * compressed by the library's pointwise encoder. */
void lazw_pointwise(tf_buf_t *b, int fmt, unsigned extra, const unsigned char *recs, size_t rec, size_t n,
                           size_t chunk) {
    hd__laz14_items_t it = {0, {0}, {0}, {0}};
    add_item(&it, 6, 20, 2);
    if (fmt == 1 || fmt == 3) add_item(&it, 7, 8, 2);
    if (fmt >= 2) add_item(&it, 8, 6, 2);
    if (extra) add_item(&it, 0, extra, 2);
    laz_file(b, fmt, &it, recs, rec, n, chunk, 0);
}


/* LAS 1.4 records (formats 6, 7, 8) with every field varying. */
unsigned char *lazw_rich_records14(gen_rng_t *g, int fmt, unsigned extra, size_t n, size_t *rec, int channels) {
    *rec = (fmt == 6 || fmt == 9 ? 30 : fmt == 7 ? 36 : 38) + (fmt >= 9 ? 29 : 0) + extra;
    unsigned char *r = calloc(n, *rec);
    int32_t x = 0, y = 0, z = 0;
    uint64_t t = 0x41C0000000000000ull;
    uint16_t rgb[4] = {100, 200, 300, 400}, scan = 0, inten = 900, psid = 3;
    unsigned chan = 0, cls = 2, ud = 7, flags = 0;
    unsigned char wave[1] = {1};
    uint64_t wave_off = 1000;
    uint32_t wave_size = 256, wave_ret = 0x3f800000, wave_xyz[3] = {0, 0, 0x3f000000};
    for (size_t k = 0; k < n; k++) {
        unsigned char *p = r + k * *rec;
        uint64_t u = gen_u64(g), v = gen_u64(g);
        x += (int32_t)(u % 2001) - 1000, y += (int32_t)(u >> 16 & 255) - 128, z += (int32_t)(u >> 24 & 15) - 7;
        if (u % 97 == 0) x = (int32_t)gen_u64(g);
        if (u % 89 == 0) z = (int32_t)gen_u64(g);
        for (int b = 0; b < 4; b++) p[b] = (unsigned char)(x >> 8 * b), p[4 + b] = (unsigned char)(y >> 8 * b), p[8 + b] = (unsigned char)(z >> 8 * b);
        if (v % 5 == 0) inten = (uint16_t)(v >> 8);
        else if (v % 5 == 1) inten = (uint16_t)(inten + (v >> 8 & 15));
        p[12] = (unsigned char)inten, p[13] = (unsigned char)(inten >> 8);
        unsigned nr = u >> 32 & 15 ? 1 + (unsigned)(u >> 36) % 5 : (unsigned)(u >> 40) & 15;
        unsigned ret = u >> 44 & 7 ? 1 + (unsigned)(u >> 47) % (nr ? nr : 1) : (unsigned)(u >> 50) & 15;
        p[14] = (unsigned char)(ret | nr << 4);
        if (channels && v % 11 == 0) chan = (unsigned)(v >> 12) & 3;
        if (v % 13 == 0) flags = (unsigned)(v >> 16) & 15;
        p[15] = (unsigned char)(flags | chan << 4 | (u >> 53 & 1) << 6 | (v % 31 == 0) << 7);
        if (v % 7 == 0) cls = (unsigned)(v >> 20) & 255;
        p[16] = (unsigned char)cls;
        if (v % 17 == 0) ud = (unsigned)(v >> 28) & 255;
        p[17] = (unsigned char)ud;
        if (v % 3 == 0) scan = (uint16_t)(scan + (int)(v >> 36 & 31) - 15);
        else if (v % 19 == 1) scan = (uint16_t)(v >> 40);
        p[18] = (unsigned char)scan, p[19] = (unsigned char)(scan >> 8);
        if (v % 23 == 0) psid = (uint16_t)(v >> 44);
        p[20] = (unsigned char)psid, p[21] = (unsigned char)(psid >> 8);
        uint64_t w = gen_u64(g);
        t = w % 4 == 0 ? t : w % 4 == 1 ? t + 1000 : w % 4 == 2 ? t + (w >> 8 & 0xFFFFF) : w % 16 == 3 ? t + (w << 30) : t - 5;
        for (int b = 0; b < 8; b++) p[22 + b] = (unsigned char)(t >> 8 * b);
        size_t off = 30;
        if (fmt == 7 || fmt == 8 || fmt == 10) {
            uint64_t c = gen_u64(g);
            if (c % 3 == 0) rgb[0] = rgb[1] = rgb[2] = (uint16_t)(c >> 8); /* grey */
            else if (c % 3 == 1) rgb[0] = (uint16_t)(rgb[0] + (c >> 8 & 15)), rgb[2] = (uint16_t)(c >> 24);
            if (c % 5 == 0) rgb[1] = (uint16_t)(c >> 40);
            if (c % 7 == 0) rgb[3] = (uint16_t)(c >> 44);
            for (int q = 0; q < (fmt == 7 ? 3 : 4); q++) p[off + 2 * q] = (unsigned char)rgb[q], p[off + 2 * q + 1] = (unsigned char)(rgb[q] >> 8);
            off += fmt == 7 ? 6 : 8;
        }
        if (fmt >= 9) { /* a wave packet descriptor: index, offset, size, return point, x, y, z */
            uint64_t c = gen_u64(g);
            if (c % 5 == 0) wave[0] = (unsigned char)(c >> 8);
            wave_off = c % 4 == 0 ? wave_off : c % 4 == 1 ? wave_off + wave_size : c % 8 == 2 ? wave_off + (c >> 20 & 0xFFFF) : c % 8 == 3 ? wave_off - 7 : c % 8 == 6 ? gen_u64(g) : wave_off + (c << 33);
            if (c % 3 == 0) wave_size = (uint32_t)(c >> 40 & 1023);
            if (c % 7 == 0) wave_ret = (uint32_t)gen_u64(g);
            for (int q = 0; q < 3; q++)
                if (c >> (50 + q) & 1) wave_xyz[q] = (uint32_t)gen_u64(g);
            p[off] = wave[0];
            for (int b = 0; b < 8; b++) p[off + 1 + b] = (unsigned char)(wave_off >> 8 * b);
            for (int b = 0; b < 4; b++) {
                p[off + 9 + b] = (unsigned char)(wave_size >> 8 * b), p[off + 13 + b] = (unsigned char)(wave_ret >> 8 * b);
                for (int q = 0; q < 3; q++) p[off + 17 + 4 * q + b] = (unsigned char)(wave_xyz[q] >> 8 * b);
            }
            off += 29;
        }
        for (unsigned e = 0; e < extra; e++) p[off + e] = (unsigned char)(k % 7 ? 40 + e : gen_u64(g));
        if (extra > 1 && k % 11 != 0) p[off + 1] = 9; /* a byte that changes rarely */
    }
    return r;
}

/* A layered LAZ file (LAS 1.4, LASzip compressor 3, items of `version`,
 * chunks of `chunk` points) of the records, compressed by the library's
 * layered encoder (hd__laz14_encode, src/io/laz14.c). */
void lazw_layered(tf_buf_t *b, int fmt, unsigned extra, const unsigned char *recs, size_t rec, size_t n, size_t chunk,
                  unsigned version) {
    hd__laz14_items_t it = {0, {0}, {0}, {0}};
    add_item(&it, 10, 30, version);
    if (fmt == 7) add_item(&it, 11, 6, version);
    if (fmt == 8 || fmt == 10) add_item(&it, 12, 8, version);
    if (fmt >= 9) add_item(&it, 13, 29, version);
    if (extra) add_item(&it, 14, extra, version);
    laz_file(b, fmt, &it, recs, rec, n, chunk, 1);
}

static uint64_t le_of(const unsigned char *p, int n) {
    uint64_t v = 0;
    for (int i = n - 1; i >= 0; i--) v = v << 8 | p[i];
    return v;
}

unsigned char *lazw_decode_records(const char *path, const unsigned char *d, size_t size, size_t *n, size_t *rec,
                                   hd_error_t *err) {
    hd__file_t f = {path, d, size};
    hd_read_options_t o;
    hd_read_options_init(&o);
    hd__sink_t sink;
    hd__sink_init(&sink, HD_FLOAT64);
    hd__read_t r = {&f, &o, 1, &sink, NULL, 0, err, 0, 0, 0};
    hd__las_header_t h;
    memset(&h, 0, sizeof h);
    h.minor = d[25], h.fmt = d[104] & 63, h.header = le_of(d + 94, 2), h.offset = le_of(d + 96, 4), h.rec = le_of(d + 105, 2);
    h.count = d[25] >= 4 ? le_of(d + 247, 8) : le_of(d + 107, 4), h.n_vlr = (uint32_t)le_of(d + 100, 4);
    hd__laz_chunks_t c;
    if (hd__laz_chunks(&r, &h, &c)) return NULL;
    unsigned char *out = calloc(h.count + 1, h.rec);
    for (size_t k = 0; out && k < c.n_chunks; k++)
        if (hd__laz_chunk_records(&r, &h, &c, k, out + c.first[k] * h.rec)) {
            free(out);
            out = NULL;
        }
    hd__laz_chunks_free(&c);
    hd__sink_free(&sink);
    *n = h.count, *rec = h.rec;
    return out;
}

/* ---- COPC ---------------------------------------------------------------- */
static void put_at(unsigned char *p, uint64_t v, int n) {
    for (int i = 0; i < n; i++) p[i] = (unsigned char)(v >> 8 * i);
}

static void copc_entry(tf_buf_t *b, int32_t level, int32_t x, uint64_t offset, int32_t bytes, int32_t count) {
    tf_u32(b, (uint32_t)level, 0), tf_u32(b, (uint32_t)x, 0), tf_u32(b, 0, 0), tf_u32(b, 0, 0);
    tf_u64(b, offset, 0), tf_u32(b, (uint32_t)bytes, 0), tf_u32(b, (uint32_t)count, 0);
}

void lazw_copc(tf_buf_t *out, const unsigned char *laz, size_t size, const size_t *chunk, const size_t *counts, size_t nc) {
    enum { INFO = 54 + 160 };
    assert(nc >= 3 && laz[25] == 4 && le_of(laz + 94, 2) == 375);
    size_t base = out->size, offset = (size_t)le_of(laz + 96, 4), table = (size_t)le_of(laz + offset, 8);
    tf_put(out, laz, 375);
    unsigned char *h = out->data + base;
    put_at(h + 96, offset + INFO, 4);
    put_at(h + 100, le_of(laz + 100, 4) + 1, 4);
    /* the info VLR: centre, halfsize, spacing, root page, GPS times */
    char user[16] = "copc", desc[32] = "COPC info (tests)";
    tf_u16(out, 0, 0), tf_put(out, user, 16), tf_u16(out, 1, 0), tf_u16(out, 160, 0), tf_put(out, desc, 32);
    size_t info = out->size - base;
    for (int i = 0; i < 5; i++) tf_f64(out, i < 3 ? 0.0 : i == 3 ? 1000.0 : 10.0, 0);
    tf_u64(out, 0, 0), tf_u64(out, 0, 0); /* the root page, below */
    for (int i = 0; i < 2 + 11; i++) tf_u64(out, 0, 0);
    tf_put(out, laz + 375, size - 375);
    put_at(out->data + base + offset + INFO, table + INFO, 8);
    /* the hierarchy EVLR: the child page, then the root page */
    uint64_t evlr = out->size - base, child = evlr + 60, child_size = 32 * (nc - 2), root = child + child_size;
    put_at(out->data + base + 235, evlr, 8);
    put_at(out->data + base + 243, 2, 4);
    char huser[16] = "copc", hdesc[32] = "COPC hierarchy (tests)";
    tf_u16(out, 0, 0), tf_put(out, huser, 16), tf_u16(out, 1000, 0), tf_u64(out, child_size + 4 * 32, 0);
    tf_put(out, hdesc, 32);
    for (size_t k = 2; k < nc; k++)
        copc_entry(out, 2, (int32_t)k, chunk[k] + INFO, (int32_t)((k + 1 < nc ? chunk[k + 1] : table) - chunk[k]),
                   (int32_t)counts[k]);
    copc_entry(out, 0, 0, chunk[0] + INFO, (int32_t)(chunk[1] - chunk[0]), (int32_t)counts[0]);
    copc_entry(out, 1, 0, chunk[1] + INFO, (int32_t)(chunk[2] - chunk[1]), (int32_t)counts[1]);
    copc_entry(out, 1, 1, 0, 0, 0);                           /* an empty node */
    copc_entry(out, 1, 2, child, (int32_t)child_size, -1); /* the child page */
    put_at(out->data + base + info + 40, root, 8);
    put_at(out->data + base + info + 48, 4 * 32, 8);
    char ouser[16] = "someone", odesc[32] = "kept";
    tf_u16(out, 0, 0), tf_put(out, ouser, 16), tf_u16(out, 9, 0), tf_u64(out, 4, 0), tf_put(out, odesc, 32);
    tf_put(out, "EVLR", 4);
}

typedef struct {
    const unsigned char *d;
    uint64_t data, end;       /* the hierarchy EVLR's data */
    size_t nc;
    uint64_t *start, *first;  /* per chunk (nc + 1) */
    uint32_t *counts;
    unsigned char *seen;
    lazw_node_t *nodes;
    size_t max, n;
    char *why;
    size_t why_len;
} copc_walk_t;

static int fail(copc_walk_t *W, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(W->why, W->why_len, fmt, ap);
    va_end(ap);
    return -1;
}

static int copc_page(copc_walk_t *W, uint64_t at, uint64_t size, int depth) {
    if (at < W->data || at > W->end || size > W->end - at || size % 32)
        return fail(W, "page at %llu (%llu bytes) is not inside the hierarchy EVLR", (unsigned long long)at,
                    (unsigned long long)size);
    if (depth > 64) return fail(W, "pages nest deeper than 64");
    for (uint64_t q = at; q < at + size; q += 32) {
        const unsigned char *e = W->d + q;
        uint64_t off = le_of(e + 16, 8);
        uint32_t bytes = (uint32_t)le_of(e + 24, 4);
        int32_t count = (int32_t)le_of(e + 28, 4);
        if (count == -1) {
            if (copc_page(W, off, bytes, depth + 1)) return -1;
            continue;
        }
        if (count == 0) {
            if (off != 0 || bytes != 0)
                return fail(W, "entry at byte %llu: no points, offset %llu and %u bytes (0 and 0 expected)",
                            (unsigned long long)q, (unsigned long long)off, bytes);
            continue;
        }
        size_t k = 0;
        while (k < W->nc && W->start[k] != off) k++;
        if (k == W->nc) return fail(W, "entry at byte %llu: offset %llu is no chunk's start", (unsigned long long)q,
                                    (unsigned long long)off);
        if (bytes != W->start[k + 1] - W->start[k] || count < 0 || (uint32_t)count != W->counts[k])
            return fail(W, "entry at byte %llu: %u bytes, %d points; chunk %zu has %llu bytes, %u points",
                        (unsigned long long)q, bytes, count, k, (unsigned long long)(W->start[k + 1] - W->start[k]),
                        W->counts[k]);
        if (W->seen[k]++) return fail(W, "chunk %zu is two nodes", k);
        if (W->n == W->max) return fail(W, "more than %zu nodes", W->max);
        lazw_node_t *nd = &W->nodes[W->n++];
        for (int i = 0; i < 4; i++) nd->key[i] = (int32_t)le_of(e + 4 * i, 4);
        nd->first = W->first[k], nd->count = (uint64_t)count;
    }
    return 0;
}

/* The chunk table at `table` (variable sizes: counts and bytes). */
static int copc_table(copc_walk_t *W, size_t size, uint64_t offset, uint64_t table) {
    if (table + 8 > size || le_of(W->d + table, 4) != 0) return fail(W, "no chunk table at %llu", (unsigned long long)table);
    W->nc = (size_t)le_of(W->d + table + 4, 4);
    W->start = calloc(W->nc + 1, 8), W->first = calloc(W->nc + 1, 8), W->counts = calloc(W->nc + 1, 4);
    W->seen = calloc(W->nc + 1, 1);
    hd__intcoder_t ic;
    icnew(&ic, 32, 2);
    hd__dec_t dec;
    hd__dec_init(&dec, W->d + table + 8, size - table - 8);
    uint32_t pc = 0, pb = 0;
    W->start[0] = offset + 8;
    for (size_t k = 0; k < W->nc; k++) {
        pc = W->counts[k] = (uint32_t)hd__ic_decode(&ic, &dec, (int32_t)pc, 0);
        pb = (uint32_t)hd__ic_decode(&ic, &dec, (int32_t)pb, 1);
        W->start[k + 1] = W->start[k] + pb;
        W->first[k + 1] = W->first[k] + pc;
    }
    hd__intcoder_free(&ic);
    if (W->start[W->nc] != table) return fail(W, "the chunks end at %llu, the table starts at %llu",
                                              (unsigned long long)W->start[W->nc], (unsigned long long)table);
    return 0;
}

int lazw_copc_nodes(const unsigned char *d, size_t size, lazw_node_t *nodes, size_t max, size_t *n, char *why,
                    size_t why_len) {
    copc_walk_t W = {d, 0, 0, 0, NULL, NULL, NULL, NULL, nodes, max, 0, why, why_len};
    int rc = 0;
    uint64_t header = le_of(d + 94, 2), offset = le_of(d + 96, 4);
    if (size < 375 || d[25] != 4 || header < 375 || header + 54 + 160 > size || memcmp(d + header + 2, "copc\0", 5) != 0 ||
        le_of(d + header + 18, 2) != 1 || le_of(d + header + 20, 2) != 160)
        rc = fail(&W, "the first VLR is not COPC's info VLR (user copc, record 1, 160 bytes)");
    uint64_t evlr = le_of(d + 235, 8), n_evlr = le_of(d + 243, 4);
    for (uint64_t i = 0; rc == 0 && i < n_evlr; i++) {
        if (evlr + 60 > size || le_of(d + evlr + 20, 8) > size - evlr - 60) rc = fail(&W, "EVLR %llu runs past the end",
                                                                                     (unsigned long long)i + 1);
        else if (memcmp(d + evlr + 2, "copc\0", 5) == 0 && le_of(d + evlr + 18, 2) == 1000)
            W.data = evlr + 60, W.end = evlr + 60 + le_of(d + evlr + 20, 8);
        if (rc == 0) evlr += 60 + le_of(d + evlr + 20, 8);
    }
    if (rc == 0 && !W.data) rc = fail(&W, "no EVLR of user copc, record 1000");
    if (rc == 0 && offset + 8 <= size) rc = copc_table(&W, size, offset, le_of(d + offset, 8));
    if (rc == 0) rc = copc_page(&W, le_of(d + header + 54 + 40, 8), le_of(d + header + 54 + 48, 8), 0);
    for (size_t k = 0; rc == 0 && k < W.nc; k++)
        if (!W.seen[k]) rc = fail(&W, "chunk %zu is no node", k);
    if (rc == 0 && W.first[W.nc] != le_of(d + 247, 8))
        rc = fail(&W, "the nodes hold %llu points, the header says %llu", (unsigned long long)W.first[W.nc],
                  (unsigned long long)le_of(d + 247, 8));
    free(W.start), free(W.first), free(W.counts), free(W.seen);
    *n = W.n;
    return rc;
}
