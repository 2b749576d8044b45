/*
 * write_lazpw.c -- fields written back into pointwise LAZ (LAS point
 * formats 0-3, LASzip compressor 2), or the points past a threshold; and
 * the points past a threshold of layered LAZ (formats 6-10, compressor 3),
 * whose chunks are decoded to whole records and encoded again, every
 * layer, by laz14.c, the rest as below (the items' versions kept, a BYTE14
 * item grown or added for the fields).
 *
 * Pointwise LAZ codes every field of a point in one stream per chunk, so
 * the fields' bytes cannot be added beside the old data: every chunk is
 * decoded to whole records (laz.c, items of version 2) and the records,
 * each with its values' 8 bytes a field after it, are compressed again by this
 * file's encoder: POINT10, GPSTIME11, RGB12 and BYTE, version 2 each, the
 * mirror of laz.c's decoder (the same models, contexts and predictions;
 * lazcoder.h has the coder):
 *  - POINT10 v2: a symbol of 64 saying which of the return byte,
 *    intensity (kept per return context m), classification, scan angle,
 *    user data, point source changed; each changed one (bytes by a model
 *    chosen by their last value, the scan angle as a difference, the
 *    others by the integer compressor); then dx and dy against the median
 *    of the last five of context m and z against the last z of the return
 *    level, their contexts from the magnitudes k of the previous ones.
 *  - GPSTIME11 v2: the decoder follows four sequences of times; this
 *    encoder uses one of its codings for each point: unchanged, a
 *    difference that fits 32 bits (against 0 or the sequence's last
 *    difference), or the whole value (a new sequence).  Any such choice
 *    decodes to the same times in every LASzip decoder; LASzip's own
 *    encoder also uses multiples of the last difference and switches back
 *    to older sequences, which only compress better.
 *  - RGB12 v2: which of the six bytes changed and whether the colour is
 *    grey (a symbol of 128); red's bytes as differences; green's and
 *    blue's, when not grey, as corrections to red's difference (for blue
 *    averaged with green's) added to their last value and clamped to a
 *    byte.
 *  - BYTE v2: each extra byte as its difference to its last value, one
 *    model per byte.
 * Chunks keep the input's point counts when every point is written; a
 * subset is cut into chunks of HD__LAZ_CHUNK points.  The header, VLRs and
 * chunk table are written as for layered LAZ; the header is written again
 * and the chunk table's place patched once the chunks are out (the file
 * is a regular temporary, so it can seek), which keeps one input chunk and
 * one output chunk in memory at a time.
 */
#include "io.h"
#include "lasfield.h"
#include "laz14.h"
#include "lazcoder.h"

#include <errno.h>
#include <stdlib.h>
#include <sys/types.h>

enum { IT_BYTE = 0, IT_POINT10 = 6, IT_GPSTIME11 = 7, IT_RGB12 = 8 };
#define HD__LAZ_CHUNK 50000 /* LASzip's default chunk size */

typedef struct {
    hd__pw_models_t m; /* the items' models, version 2 (lazcoder.h) */
    uint16_t last_int[16];
    int32_t last_h[8];
    unsigned char last[20];
    int64_t t[4];
    int32_t gdiff[4];
    unsigned glast, gnext;
    uint16_t rgb[3];
    unsigned nb;
    hd__symmodel_t *bm;
    unsigned char *blast;
    int oom;
} pwe_t;

static void pwe_free(pwe_t *p) {
    hd__pw_models_free(&p->m);
    for (unsigned i = 0; p->bm && i < p->nb; i++) hd__symmodel_free(&p->bm[i]);
    free(p->bm);
    free(p->blast);
}

/* The models of a chunk, started from its first record r (items: the
 * output's, sizes sz). */
static int pwe_start(pwe_t *p, const unsigned char *r, const unsigned *type, const unsigned *sz, unsigned n_items) {
    memset(p, 0, sizeof *p);
    int rc = hd__pw_point10_new(&p->m, 1);
    rc = rc ? rc : hd__pw_gps11_new(&p->m, 1);
    rc = rc ? rc : hd__pw_rgb12_new(&p->m, 1);
    memcpy(p->last, r, 20);
    size_t off = 20;
    for (unsigned i = 1; i < n_items && rc == HD_OK; i++) {
        if (type[i] == IT_GPSTIME11) p->t[0] = (int64_t)hd__ld_u64(r + off, 0);
        if (type[i] == IT_RGB12)
            for (int c = 0; c < 3; c++) p->rgb[c] = hd__ld_u16(r + off + 2 * c, 0);
        if (type[i] == IT_BYTE) {
            p->nb = sz[i];
            p->bm = calloc(p->nb, sizeof *p->bm);
            p->blast = malloc(p->nb);
            if (!p->bm || !p->blast) return HD_ENOMEM;
            memcpy(p->blast, r + off, p->nb);
            for (unsigned k = 0; k < p->nb && rc == HD_OK; k++) rc = hd__symmodel_new(&p->bm[k], 256);
        }
        off += sz[i];
    }
    return rc;
}

/* The model at *slot (256 symbols), created on first use. */
static hd__symmodel_t *model(pwe_t *p, hd__symmodel_t **slot) {
    if (!*slot) {
        hd__symmodel_t *m = malloc(sizeof *m);
        if (!m || hd__symmodel_new(m, 256)) {
            free(m);
            p->oom = 1;
            return NULL;
        }
        *slot = m;
    }
    return *slot;
}

static void byte_by_last(pwe_t *p, hd__enc_t *e, hd__symmodel_t **models, unsigned char *last, unsigned char now) {
    hd__symmodel_t *m = model(p, &models[*last]);
    if (m) hd__enc_symbol(e, m, now);
    *last = now;
}

static void point10(pwe_t *p, hd__enc_t *e, const unsigned char *r) {
    unsigned char *L = p->last;
    unsigned n = (r[14] >> 3) & 7, ret = r[14] & 7, m = hd__laz_rmap10[n][ret], l = hd__laz_level(n, ret);
    uint16_t inten = hd__ld_u16(r + 12, 0);
    unsigned changed = (r[14] != L[14]) << 5 | (inten != p->last_int[m]) << 4 | (r[15] != L[15]) << 3 |
                       (r[16] != L[16]) << 2 | (r[17] != L[17]) << 1 | (hd__ld_u16(r + 18, 0) != hd__ld_u16(L + 18, 0));
    hd__enc_symbol(e, &p->m.changed, changed);
    if (changed & 32) byte_by_last(p, e, p->m.bitbyte, &L[14], r[14]);
    if (changed & 16) {
        hd__ic_encode(&p->m.intensity, e, p->last_int[m], inten, m < 3 ? m : 3);
        p->last_int[m] = inten;
    }
    if (changed & 8) byte_by_last(p, e, p->m.cls, &L[15], r[15]);
    if (changed & 4) {
        hd__enc_symbol(e, &p->m.scan[(r[14] >> 6) & 1], (unsigned)(r[16] - L[16]) & 255);
        L[16] = r[16];
    }
    if (changed & 2) byte_by_last(p, e, p->m.user, &L[17], r[17]);
    if (changed & 1) {
        hd__ic_encode(&p->m.psid, e, hd__ld_u16(L + 18, 0), hd__ld_u16(r + 18, 0), 0);
        L[18] = r[18], L[19] = r[19];
    }
    int32_t X = (int32_t)hd__ld_u32(r, 0), Y = (int32_t)hd__ld_u32(r + 4, 0), Z = (int32_t)hd__ld_u32(r + 8, 0);
    int32_t dx = (int32_t)((uint32_t)X - hd__ld_u32(L, 0)), dy = (int32_t)((uint32_t)Y - hd__ld_u32(L + 4, 0));
    hd__ic_encode(&p->m.dx, e, p->m.mx[m].v[2], dx, n == 1);
    hd__median5_add(&p->m.mx[m], dx);
    hd__ic_encode(&p->m.dy, e, p->m.my[m].v[2], dy, (n == 1) + hd__laz_kctx(p->m.dx.k, 20));
    hd__median5_add(&p->m.my[m], dy);
    hd__ic_encode(&p->m.dz, e, p->last_h[l], Z, (n == 1) + hd__laz_kctx((p->m.dx.k + p->m.dy.k) / 2, 18));
    p->last_h[l] = Z;
    memcpy(L, r, 12);
}

/* GPSTIME11 v2, one of the decoder's codings per point (see the top). */
static void gpstime(pwe_t *p, hd__enc_t *e, int64_t T) {
    unsigned L = p->glast;
    int64_t diff = (int64_t)((uint64_t)T - (uint64_t)p->t[L]);
    int fits = diff >= INT32_MIN && diff <= INT32_MAX;
    if (p->gdiff[L] == 0) {
        hd__enc_symbol(e, &p->m.gzero, T == p->t[L] ? 0 : fits ? 1 : 2);
        if (T == p->t[L]) return;
        if (fits) {
            hd__ic_encode(&p->m.gic, e, 0, (int32_t)diff, 0);
            p->gdiff[L] = (int32_t)diff;
            p->t[L] = T;
            return;
        }
    } else {
        hd__enc_symbol(e, &p->m.gmulti, T == p->t[L] ? 511 : fits ? 1 : 512);
        if (T == p->t[L]) return;
        if (fits) {
            hd__ic_encode(&p->m.gic, e, p->gdiff[L], (int32_t)diff, 1);
            p->t[L] = T;
            return;
        }
    }
    /* the whole value, as a new sequence */
    p->gnext = (p->gnext + 1) & 3;
    hd__ic_encode(&p->m.gic, e, (int32_t)((uint64_t)p->t[L] >> 32), (int32_t)((uint64_t)T >> 32), 8);
    hd__enc_raw(e, 16, (uint32_t)T & 0xFFFF);
    hd__enc_raw(e, 16, ((uint32_t)T >> 16) & 0xFFFF);
    p->t[p->gnext] = T;
    p->glast = p->gnext;
    p->gdiff[p->glast] = 0;
}

static unsigned clamp8(int v) { return v < 0 ? 0u : v > 255 ? 255u : (unsigned)v; }

static void rgb12(pwe_t *p, hd__enc_t *e, const unsigned char *r) {
    uint16_t it[3], *last = p->rgb;
    for (int c = 0; c < 3; c++) it[c] = hd__ld_u16(r + 2 * c, 0);
    unsigned sym = ((last[0] & 255) != (it[0] & 255)) | ((last[0] >> 8) != (it[0] >> 8)) << 1 |
                   ((last[1] & 255) != (it[1] & 255)) << 2 | ((last[1] >> 8) != (it[1] >> 8)) << 3 |
                   ((last[2] & 255) != (it[2] & 255)) << 4 | ((last[2] >> 8) != (it[2] >> 8)) << 5 |
                   (it[0] != it[1] || it[0] != it[2]) << 6;
    hd__enc_symbol(e, &p->m.used, sym);
    int dl = (int)(it[0] & 255) - (int)(last[0] & 255), dh = (int)(it[0] >> 8) - (int)(last[0] >> 8);
    if (sym & 1) hd__enc_symbol(e, &p->m.cdiff[0], (unsigned)dl & 255);
    if (sym & 2) hd__enc_symbol(e, &p->m.cdiff[1], (unsigned)dh & 255);
    if (sym & 64) {
        if (sym & 4) hd__enc_symbol(e, &p->m.cdiff[2], (unsigned)((int)(it[1] & 255) - (int)clamp8(dl + (last[1] & 255))) & 255);
        if (sym & 16) {
            int d = (dl + ((int)(it[1] & 255) - (int)(last[1] & 255))) / 2;
            hd__enc_symbol(e, &p->m.cdiff[4], (unsigned)((int)(it[2] & 255) - (int)clamp8(d + (last[2] & 255))) & 255);
        }
        if (sym & 8) hd__enc_symbol(e, &p->m.cdiff[3], (unsigned)((int)(it[1] >> 8) - (int)clamp8(dh + (last[1] >> 8))) & 255);
        if (sym & 32) {
            int d = (dh + ((int)(it[1] >> 8) - (int)(last[1] >> 8))) / 2;
            hd__enc_symbol(e, &p->m.cdiff[5], (unsigned)((int)(it[2] >> 8) - (int)clamp8(d + (last[2] >> 8))) & 255);
        }
    }
    memcpy(last, it, sizeof it);
}

static void bytes(pwe_t *p, hd__enc_t *e, const unsigned char *r) {
    for (unsigned k = 0; k < p->nb; k++) {
        hd__enc_symbol(e, &p->bm[k], (unsigned)(r[k] - p->blast[k]) & 255);
        p->blast[k] = r[k];
    }
}

int hd__laz_encode_pointwise(const unsigned char *recs, size_t n, size_t rec, const unsigned *type, const unsigned *sz,
                        unsigned n_items, hd__enc_t *e) {
    pwe_t *p = malloc(sizeof *p);
    if (!p) return HD_ENOMEM;
    hd__enc_reset(e);
    int rc = pwe_start(p, recs, type, sz, n_items);
    for (size_t i = 1; i < n && rc == HD_OK; i++) {
        const unsigned char *r = recs + i * rec;
        point10(p, e, r);
        size_t off = 20;
        for (unsigned t = 1; t < n_items; t++) {
            if (type[t] == IT_GPSTIME11) gpstime(p, e, (int64_t)hd__ld_u64(r + off, 0));
            else if (type[t] == IT_RGB12) rgb12(p, e, r + off);
            else bytes(p, e, r + off);
            off += sz[t];
        }
    }
    if (rc == HD_OK) hd__enc_done(e);
    if (rc == HD_OK && (p->oom || e->oom)) rc = HD_ENOMEM;
    pwe_free(p);
    free(p);
    return rc;
}

/* The chunk table's entries: per chunk its point count (variable chunk
 * sizes only) and its byte size, each predicted by the previous chunk's,
 * in one stream (the table's version and chunk count precede it). */
int hd__laz_table_encode(int variable, size_t nc, const uint32_t *counts, const uint64_t *bytes, hd__enc_t *e) {
    hd__intcoder_t ic;
    if (hd__intcoder_new(&ic, 32, 2)) return HD_ENOMEM;
    hd__enc_reset(e);
    for (size_t k = 0; k < nc; k++) {
        if (variable) hd__ic_encode(&ic, e, k ? (int32_t)counts[k - 1] : 0, (int32_t)counts[k], 0);
        hd__ic_encode(&ic, e, k ? (int32_t)bytes[k - 1] : 0, (int32_t)bytes[k], 1);
    }
    hd__enc_done(e);
    hd__intcoder_free(&ic);
    return e->oom ? HD_ENOMEM : HD_OK;
}

typedef struct {
    hd__writer_t *w;
    hd__las_plan_t *pl;
    unsigned type[32], size[32], version[32], n_items;
    int layered; /* LASzip compressor 3 (laz14.c encodes the chunks) */
    unsigned char *vlr;  /* the output's LASzip VLR data */
    size_t vlr_len;
    uint32_t *counts;    /* per output chunk */
    uint64_t *bytes;
    size_t n_chunks, cap_chunks;
    hd__enc_t enc;
    uint64_t kept, by_return[16];
    uint64_t *kept_in;   /* per input chunk: its points kept (COPC subsets) */
    double bounds[6], scale[3], shift[3];
} pw_t;

/* The output's items (every input item of version 2; the BYTE item grown
 * by 8 a field, or added) and its LASzip VLR (the input's, items rewritten;
 * compressor 2, the chunk size `chunk`). */
static int plan_items(pw_t *z, const hd__laz_chunks_t *c, uint32_t chunk) {
    hd__writer_t *w = z->w;
    for (unsigned i = 0; i < c->n_items && !c->layered; i++)
        if (c->version[i] != 2)
            return hd__err(w->err, HD_EUNSUPPORTED,
                           "%s: LASzip item %u is of version %u: a field is written into pointwise LAZ of version 2 "
                           "items (LASzip 2 and later) only",
                           w->in->name, i + 1, c->version[i]);
    z->n_items = c->n_items;
    z->layered = c->layered;
    memcpy(z->type, c->type, sizeof z->type);
    memcpy(z->size, c->size, sizeof z->size);
    for (unsigned i = 0; i < c->n_items; i++) z->version[i] = c->layered ? c->version[i] : 2;
    unsigned nb = (unsigned)(8 * w->nf), bytes = c->layered ? HD__LAZ_IT_BYTE14 : IT_BYTE;
    if (z->pl->add) { /* a new BYTE14 item takes POINT14's version */
        if (z->type[z->n_items - 1] == bytes) z->size[z->n_items - 1] += nb;
        else z->type[z->n_items] = bytes, z->version[z->n_items] = z->version[0], z->size[z->n_items++] = nb;
    }
    const unsigned char *v = w->in->data + c->vlr_at;
    size_t tail = c->vlr_len - (34 + 6 * (size_t)c->n_items); /* bytes after the items, kept */
    z->vlr_len = 34 + 6 * (size_t)z->n_items + tail;
    if (!(z->vlr = malloc(z->vlr_len))) return hd__err(w->err, HD_ENOMEM, "out of memory");
    memcpy(z->vlr, v, 34);
    z->vlr[0] = c->layered ? 3 : 2, z->vlr[1] = 0; /* layered or pointwise chunked */
    for (int b = 0; b < 4; b++) z->vlr[12 + b] = (unsigned char)(chunk >> (8 * b));
    z->vlr[32] = (unsigned char)z->n_items, z->vlr[33] = 0;
    for (unsigned i = 0; i < z->n_items; i++) {
        unsigned char *q = z->vlr + 34 + 6 * i;
        q[0] = (unsigned char)z->type[i], q[1] = 0, q[2] = (unsigned char)z->size[i], q[3] = (unsigned char)(z->size[i] >> 8);
        q[4] = (unsigned char)z->version[i], q[5] = 0;
    }
    memcpy(z->vlr + 34 + 6 * z->n_items, v + 34 + 6 * c->n_items, tail);
    return HD_OK;
}

/* Write a chunk (its first record raw, then its stream e) and note its
 * count and bytes for the chunk table; HD_OK or HD_ENOMEM. */
static int put_chunk(pw_t *z, size_t n, const unsigned char *first, const hd__enc_t *e) {
    if (z->n_chunks == z->cap_chunks) {
        size_t cap = z->cap_chunks ? 2 * z->cap_chunks : 64;
        uint32_t *c = hd__realloc_array(z->counts, cap, sizeof *c);
        if (c) z->counts = c;
        uint64_t *b = hd__realloc_array(z->bytes, cap, sizeof *b);
        if (b) z->bytes = b;
        if (!c || !b) return HD_ENOMEM;
        z->cap_chunks = cap;
    }
    z->counts[z->n_chunks] = (uint32_t)n;
    z->bytes[z->n_chunks++] = z->pl->out_rec + e->size;
    hd__w_put(z->w, first, z->pl->out_rec);
    hd__w_put(z->w, e->buf, e->size);
    return HD_OK;
}

/* The stream of the output chunk of n records recs (after its raw first
 * one) into e: HD_OK or the encoder's error code. */
static int encode_records(const pw_t *z, const unsigned char *recs, size_t n, hd__enc_t *e) {
    if (!z->layered) return hd__laz_encode_pointwise(recs, n, z->pl->out_rec, z->type, z->size, z->n_items, e);
    hd__laz14_items_t it = {z->n_items, {0}, {0}, {0}};
    memcpy(it.type, z->type, sizeof it.type);
    memcpy(it.size, z->size, sizeof it.size);
    memcpy(it.version, z->version, sizeof it.version);
    return hd__laz14_encode(recs, n, z->pl->out_rec, &it, e);
}

/* The chunks are decoded a batch of P at a time, in parallel: task t
 * decodes input chunk base + t to records and keeps the kept ones with
 * their values (kept[t], n_kept[t] of them), each task with its own
 * buffers and error; with `encode` (every point kept, the input's chunks
 * kept) the task also compresses them (enc[t]).  Without it the kept
 * records are gathered in file order into output chunks of `cap` points
 * (out, n_out: per input chunk when per = 0), and a batch of full output
 * chunks is encoded in parallel (enc) and written in order.  Either way
 * the file is the one a sequential pass would write. */
typedef struct {
    pw_t *z;
    const hd__las_header_t *h;
    const hd__laz_chunks_t *c;
    hd__read_t *r;
    size_t P, base, most, cap;
    int threads, encode;
    unsigned char **in, **kept; /* per task: its chunk's records, the kept ones with their values */
    size_t *n_kept;
    unsigned char **out; /* per output chunk of the batch: its records */
    size_t *n_out;
    hd__enc_t *enc;
    int *rc;
    hd_error_t *err;
} sub_t;

/* S's buffers for a batch of 2 per thread; HD_OK or HD_ENOMEM (with
 * w->err).  sub_free frees them, after a failure too. */
static int sub_new(sub_t *S, pw_t *z, const hd__las_header_t *h, const hd__laz_chunks_t *c, hd__read_t *r) {
    memset(S, 0, sizeof *S);
    S->z = z, S->h = h, S->c = c, S->r = r;
    for (size_t k = 0; k < c->n_chunks; k++)
        if (c->first[k + 1] - c->first[k] > S->most) S->most = (size_t)(c->first[k + 1] - c->first[k]);
    S->threads = hd__thread_count(z->w->ropt->threads, c->n_chunks);
    size_t P = S->P = 2 * (size_t)S->threads;
    S->in = calloc(P, sizeof(void *)), S->kept = calloc(P, sizeof(void *)), S->n_kept = calloc(P, sizeof(size_t));
    S->out = calloc(P, sizeof(void *)), S->n_out = calloc(P, sizeof(size_t)), S->enc = calloc(P, sizeof(hd__enc_t));
    S->rc = calloc(P, sizeof(int)), S->err = calloc(P, sizeof(hd_error_t));
    if (!S->in || !S->kept || !S->n_kept || !S->out || !S->n_out || !S->enc || !S->rc || !S->err)
        return hd__err(z->w->err, HD_ENOMEM, "out of memory");
    for (size_t t = 0; t < P; t++) hd__enc_init(&S->enc[t]);
    return HD_OK;
}

static void sub_free(sub_t *S) {
    for (size_t t = 0; t < S->P; t++) {
        if (S->in) free(S->in[t]);
        if (S->kept) free(S->kept[t]);
        if (S->out) free(S->out[t]);
        if (S->enc) hd__enc_free(&S->enc[t]);
    }
    free(S->in), free(S->kept), free(S->n_kept), free(S->out), free(S->n_out), free(S->enc), free(S->rc), free(S->err);
}

static void decode_task(void *ctx, size_t t, int worker) {
    (void)worker;
    sub_t *S = ctx;
    hd__writer_t *w = S->z->w;
    size_t k = S->base + t, n = (size_t)(S->c->first[k + 1] - S->c->first[k]), f = (size_t)S->c->first[k];
    size_t rec = S->z->pl->rec, orec = S->z->pl->out_rec;
    hd__read_t r = *S->r;
    r.err = &S->err[t];
    if (!S->in[t]) S->in[t] = hd__malloc_array(S->most + 1, rec);
    if (!S->kept[t]) S->kept[t] = hd__malloc_array(S->most + 1, orec);
    if (!S->in[t] || !S->kept[t]) {
        S->rc[t] = hd__err(&S->err[t], HD_ENOMEM, "out of memory for chunks of %zu points", S->most);
        return;
    }
    int rc = hd__laz_chunk_records(&r, S->h, S->c, k, S->in[t]);
    size_t m = 0;
    for (size_t i = 0; i < n && rc == HD_OK; i++) {
        if (!hd__w_keep(w, f + i)) continue;
        unsigned char *o = S->kept[t] + m++ * orec;
        memcpy(o, S->in[t] + i * rec, rec);
        hd__w_values(w, f + i, 0, o + rec);
    }
    S->n_kept[t] = m;
    if (rc == HD_OK && S->encode && encode_records(S->z, S->kept[t], m, &S->enc[t]))
        rc = hd__err(&S->err[t], HD_ENOMEM, "out of memory");
    S->rc[t] = rc;
}

/* Decode the batch of input chunks from S->base (*m of them); HD_OK, or
 * the error of the first chunk that failed (its byte offset included). */
static int decode_batch(sub_t *S, size_t *m) {
    size_t left = S->c->n_chunks - S->base;
    *m = left < S->P ? left : S->P;
    hd__parallel_for(S->threads, *m, decode_task, S);
    for (size_t t = 0; t < *m; t++)
        if (S->rc[t]) {
            if (S->z->w->err) *S->z->w->err = S->err[t];
            return S->rc[t];
        }
    return HD_OK;
}

static void encode_task(void *ctx, size_t t, int worker) {
    (void)worker;
    sub_t *S = ctx;
    S->rc[t] = encode_records(S->z, S->out[t], S->n_out[t], &S->enc[t]);
}

/* Encode the batch's first m output chunks and write them in order. */
static int flush_outs(sub_t *S, size_t m) {
    hd__writer_t *w = S->z->w;
    hd__parallel_for(S->threads, m, encode_task, S);
    for (size_t t = 0; t < m; t++) {
        if (S->rc[t] == HD_EINVAL)
            return hd__err(w->err, HD_EINVAL, "%s: internal: a record would not decode back to itself", w->in->name);
        if (S->rc[t]) return hd__err(w->err, S->rc[t], "%s: %s", w->in->name, hd_strerror(S->rc[t]));
        if (put_chunk(S->z, S->n_out[t], S->out[t], &S->enc[t])) return hd__err(w->err, HD_ENOMEM, "out of memory");
        S->n_out[t] = 0;
    }
    return HD_OK;
}

/* Record o (kept, with its values) into the output chunk being gathered,
 * *full; a batch of P full ones is encoded and written.  HD_OK or the error. */
static int gather(sub_t *S, const unsigned char *o, size_t *full) {
    pw_t *z = S->z;
    size_t orec = z->pl->out_rec;
    z->by_return[hd__las_return(o, z->pl->fmt)]++;
    hd__las_bound(z->bounds, o, z->scale, z->shift, z->kept++ == 0);
    if (!S->out[*full] && !(S->out[*full] = hd__malloc_array(S->cap + 1, orec)))
        return hd__err(z->w->err, HD_ENOMEM, "out of memory for chunks of %zu points", S->cap);
    memcpy(S->out[*full] + S->n_out[*full]++ * orec, o, orec);
    if (S->n_out[*full] < S->cap) return HD_OK;
    if (++*full < S->P) return HD_OK;
    *full = 0;
    return flush_outs(S, S->P);
}

/* A subset (or every point into chunks of `per` points): the kept records
 * gathered into new chunks. */
static int write_chunks(pw_t *z, const hd__las_header_t *h, const hd__laz_chunks_t *c, hd__read_t *r, size_t per) {
    hd__writer_t *w = z->w;
    sub_t S;
    int rc = sub_new(&S, z, h, c, r);
    size_t full = 0, orec = z->pl->out_rec, m = 0;
    S.cap = per ? per : S.most;
    for (S.base = 0; rc == HD_OK && S.base < c->n_chunks && !w->werr; S.base += S.P) {
        rc = decode_batch(&S, &m);
        for (size_t t = 0; t < m && rc == HD_OK; t++) {
            if (z->kept_in) z->kept_in[S.base + t] = S.n_kept[t];
            for (size_t j = 0; j < S.n_kept[t] && rc == HD_OK; j++) rc = gather(&S, S.kept[t] + j * orec, &full);
            if (rc == HD_OK && !per && S.n_out[full] && ++full == S.P) { /* the input's chunks: one ends here */
                full = 0;
                rc = flush_outs(&S, S.P);
            }
        }
    }
    if (rc == HD_OK && !w->werr) rc = flush_outs(&S, full + (S.n_out[full] > 0));
    sub_free(&S);
    return rc;
}

/* Every point kept, the input's chunks kept: each task encodes its chunk
 * too, and the batch's chunks are written in order. */
static int write_all_parallel(pw_t *z, const hd__las_header_t *h, const hd__laz_chunks_t *c, hd__read_t *r) {
    hd__writer_t *w = z->w;
    sub_t S;
    int rc = sub_new(&S, z, h, c, r);
    size_t m = 0;
    S.encode = 1;
    for (S.base = 0; rc == HD_OK && S.base < c->n_chunks && !w->werr; S.base += S.P) {
        rc = decode_batch(&S, &m);
        for (size_t t = 0; t < m && rc == HD_OK; t++)
            if (put_chunk(z, S.n_kept[t], S.kept[t], &S.enc[t])) rc = hd__err(w->err, HD_ENOMEM, "out of memory");
    }
    z->kept = w->n;
    sub_free(&S);
    return rc;
}

/* A COPC subset's hierarchy: input chunk k's kept points are output
 * chunk j, the j-th chunk keeping a point; the EVLRs follow the table
 * ending at table_end (write_copc.c moves the entries). */
static int copc_nodes(pw_t *z, const hd__laz_chunks_t *c, uint64_t table_end, unsigned char **info, unsigned char **hier) {
    hd__writer_t *w = z->w;
    size_t nc = c->n_chunks;
    uint64_t *start = hd__calloc_array(nc + 1, sizeof *start), *bytes = hd__calloc_array(nc + 1, sizeof *bytes);
    int rc = start && bytes ? HD_OK : hd__err(w->err, HD_ENOMEM, "out of memory");
    uint64_t at = z->pl->offset + z->pl->vlr_added + 8;
    for (size_t k = 0, j = 0; rc == HD_OK && k < nc; k++) {
        if (!z->kept_in[k]) continue;
        if (j == z->n_chunks || z->counts[j] != z->kept_in[k]) {
            rc = hd__err(w->err, HD_EINVAL, "%s: internal: COPC node %zu's points are not one chunk", w->in->name, k + 1);
            break;
        }
        start[k] = at;
        at += bytes[k] = z->bytes[j++];
    }
    if (rc == HD_OK) rc = hd__copc_move(w, z->pl, c, start, bytes, z->kept_in, table_end - c->table_end, info, hier);
    free(start);
    free(bytes);
    return rc;
}

int hd__write_laz_pointwise(hd__writer_t *w, hd__las_plan_t *pl, const hd__las_header_t *h, const hd__laz_chunks_t *c,
                            hd__read_t *r) {
    if (!c->chunked)
        return hd__err(w->err, HD_EUNSUPPORTED,
                       "%s: LASzip 1.x compression (one stream, items of version 1): a field is written into "
                       "chunked pointwise LAZ (LASzip 2 and later) only",
                       w->in->name);
    pw_t z;
    memset(&z, 0, sizeof z);
    z.w = w;
    z.pl = pl;
    hd__enc_init(&z.enc);
    hd__las_scale(w->in->data, z.scale, z.shift);
    int all = w->keep == HD_KEEP_ALL;
    int copc = !all && pl->copc_at && !pl->copc_drop; /* a COPC subset: a chunk per node (write_copc.c) */
    uint32_t chunk = all || copc ? c->chunk_size : HD__LAZ_CHUNK;
    unsigned char *copc_info = NULL, *copc_hier = NULL;
    if (copc && !(z.kept_in = hd__calloc_array(c->n_chunks + 1, sizeof *z.kept_in)))
        return hd__err(w->err, HD_ENOMEM, "out of memory");
    int variable = chunk == 0 || chunk == 0xFFFFFFFFu;
    int rc = plan_items(&z, c, chunk);
    off_t head_at = 0, table_ptr = 0;
    if (rc == HD_OK) {
        pl->vlr_added += z.vlr_len - c->vlr_len;
        pl->end = c->table_end;
        /* provisional: counts, bounds and the offsets after the points are
         * written again below */
        hd__las_write_head(w, pl, 0, z.by_return, z.bounds, 0, z.vlr, c->vlr_at, z.vlr_len);
        table_ptr = ftello(w->out);
        unsigned char zero[8] = {0};
        hd__w_put(w, zero, 8);
        rc = all && pl->add ? write_all_parallel(&z, h, c, r) : write_chunks(&z, h, c, r, all || copc ? 0 : HD__LAZ_CHUNK);
    }
    if (rc == HD_OK && !w->werr) {
        off_t table = ftello(w->out);
        unsigned char head[8] = {0, 0, 0, 0};
        for (int b = 0; b < 4; b++) head[4 + b] = (unsigned char)(z.n_chunks >> (8 * b));
        hd__w_put(w, head, 8);
        if (hd__laz_table_encode(variable, z.n_chunks, z.counts, z.bytes, &z.enc)) rc = hd__err(w->err, HD_ENOMEM, "out of memory");
        hd__w_put(w, z.enc.buf, z.enc.size);
        if (rc == HD_OK && copc) rc = copc_nodes(&z, c, (uint64_t)table + 8 + z.enc.size, &copc_info, &copc_hier);
        uint64_t tail = hd__las_put_tail(w, pl, c->table_end); /* extended VLRs (COPC: the hierarchy moved) */
        uint64_t points = (uint64_t)(ftello(w->out) - table_ptr) - tail;
        if (rc == HD_OK && !w->werr && fseeko(w->out, head_at, SEEK_SET) != 0) w->werr = errno ? errno : EIO;
        hd__las_write_head(w, pl, z.kept, z.by_return, z.bounds, points, z.vlr, c->vlr_at, z.vlr_len);
        unsigned char t[8];
        hd__st_u64(t, (uint64_t)table);
        if (!w->werr && fseeko(w->out, table_ptr, SEEK_SET) != 0) w->werr = errno ? errno : EIO;
        hd__w_put(w, t, 8);
        if (!w->werr && fseeko(w->out, 0, SEEK_END) != 0) w->werr = errno ? errno : EIO;
        w->written = (size_t)z.kept;
    }
    free(copc_info);
    free(copc_hier);
    free(z.kept_in);
    free(z.vlr);
    free(z.counts);
    free(z.bytes);
    hd__enc_free(&z.enc);
    return rc;
}
