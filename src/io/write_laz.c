/*
 * write_laz.c -- fields written back into LAZ (hd_write_fields).
 *
 * Layered LAZ (LAS 1.4 point formats 6-10, LASzip compressor 3) keeps
 * every field of a point in layers of its own: a chunk is its first point
 * raw, its point count, one u32 byte size per layer, then the layers, in
 * the order of the LASzip VLR's items (POINT14's nine, RGB14's one,
 * RGBNIR14's two, WAVEPACKET14's one, BYTE14's one per extra byte).  The
 * extra bytes are the last bytes of a record and BYTE14 the last item, so
 * the 8 bytes of each field added are 8 more layers at the end of every
 * chunk: with nl = 8 * fields, the chunk's first point gets the values'
 * nl bytes, nl sizes follow the old ones, nl layers the old layers, and
 * every old byte is copied as it is.  The LASzip VLR's BYTE14 item grows
 * by nl (or a BYTE14 item of nl is added), the chunk table is encoded
 * again with the new byte sizes.
 *
 * BYTE14 (LASzip's LASwriteItemCompressed_BYTE14_v3, from the format's
 * description): per byte one stream; the models depend on the scanner
 * channel of the point (the context the POINT14 layer chooses), one
 * 256-symbol model per byte and channel, created when the channel first
 * appears in the chunk with the last bytes of the channel before it; each
 * point after the first codes (byte - last byte) mod 256, the last byte
 * being its channel's, except (item version 3, as LASzip's v3 coder does)
 * at a switch to a channel seen before in the chunk, whose point is
 * predicted from, and updates, the last bytes of the channel it follows.
 * A byte that never differs from its channel's last value within a chunk
 * gets an empty layer (size 0), which a decoder reads as "unchanged".  The
 * channels come from decoding each chunk's x/y layer (laz.c).
 *
 * A subset of a layered file changes every prediction in a chunk, so it is
 * decoded to whole records and its kept points compressed again, every
 * layer (laz14.c), by the writer of pointwise LAZ (write_lazpw.c), which
 * does the same for pointwise files (formats 0-5 interleave every field of
 * a point in one stream, so adding bytes there means compressing every
 * field again).  COPC files keep their hierarchy, moved with the chunks
 * (write_copc.c).
 */
#include "io.h"
#include "lasfield.h"
#include "laz14.h"
#include "lazcoder.h"

#include <stdlib.h>

enum { IT_POINT14 = 10, IT_BYTE14 = 14 };

/* A channel's models and last bytes, nl = 8 * nf of each. */
typedef struct {
    int used;
    unsigned char *last;
    hd__symmodel_t *m;
} bctx_t;

static int bctx_start(bctx_t *c, const unsigned char *last, size_t nl) {
    c->used = 1;
    c->last = malloc(nl);
    c->m = calloc(nl, sizeof *c->m);
    if (!c->last || !c->m) return HD_ENOMEM;
    for (size_t i = 0; i < nl; i++)
        if (hd__symmodel_new(&c->m[i], 256)) return HD_ENOMEM;
    memcpy(c->last, last, nl);
    return HD_OK;
}

static void bctx_free(bctx_t *c, size_t nl) {
    for (size_t i = 0; c->m && i < nl; i++) hd__symmodel_free(&c->m[i]);
    free(c->m);
    free(c->last);
}

/* The nl BYTE14 layers of the n points from `first` whose channels are
 * chan, into enc[0..nl-1]; size[b] 0 for a byte that never changes;
 * item and changed: nl bytes and ints of scratch. */
static int encode_bytes(const hd__writer_t *w, size_t first, size_t n, const unsigned char *chan, int v4,
                        hd__enc_t *enc, uint32_t *size, unsigned char *item, int *changed) {
    size_t nl = 8 * w->nf;
    bctx_t cx[4];
    memset(cx, 0, sizeof cx);
    memset(changed, 0, nl * sizeof *changed);
    int rc = HD_OK;
    for (size_t b = 0; b < nl; b++) hd__enc_reset(&enc[b]);
    hd__w_values(w, first, 0, item);
    unsigned cur = chan[0];
    rc = bctx_start(&cx[cur], item, nl);
    for (size_t i = 1; i < n && rc == HD_OK; i++) {
        unsigned char *last = cx[cur].last;
        if (chan[i] != cur) {
            unsigned next = chan[i];
            if (!cx[next].used) {
                if ((rc = bctx_start(&cx[next], last, nl))) break;
                last = cx[next].last;
            } else if (v4) {
                last = cx[next].last;
            } /* v3: a channel seen before predicts from (and updates) the
                 last bytes of the channel it follows, as LASzip's v3 does */
            cur = next;
        }
        bctx_t *c = &cx[cur];
        hd__w_values(w, first + i, 0, item);
        for (size_t b = 0; b < nl; b++) {
            unsigned diff = (unsigned)(item[b] - last[b]) & 255;
            hd__enc_symbol(&enc[b], &c->m[b], diff);
            if (diff) {
                changed[b] = 1;
                last[b] = item[b];
            }
        }
    }
    for (size_t b = 0; b < nl; b++) {
        if (changed[b]) hd__enc_done(&enc[b]);
        size[b] = changed[b] ? (uint32_t)enc[b].size : 0;
        if (enc[b].oom) rc = HD_ENOMEM;
    }
    for (int k = 0; k < 4; k++) bctx_free(&cx[k], nl);
    return rc;
}

/* The LASzip VLR's data with the BYTE14 item grown by nl or added: into
 * *out (malloc'd), its length in *len. */
static int new_vlr(const hd__writer_t *w, const hd__laz_chunks_t *c, unsigned char **out, size_t *len) {
    size_t nl = 8 * w->nf;
    const unsigned char *v = w->in->data + c->vlr_at;
    int grow = c->type[c->n_items - 1] == IT_BYTE14;
    *len = c->vlr_len + (grow ? 0 : 6);
    unsigned char *p = malloc(*len);
    if (!p) return hd__err(w->err, HD_ENOMEM, "out of memory");
    memcpy(p, v, c->vlr_len);
    size_t item = 34 + 6 * (size_t)(c->n_items - 1);
    if (grow) {
        unsigned sz = c->size[c->n_items - 1] + (unsigned)nl;
        p[item + 2] = (unsigned char)sz;
        p[item + 3] = (unsigned char)(sz >> 8);
    } else {
        unsigned n = c->n_items + 1, version = hd__ld_u16(v + 34 + 4, 0); /* POINT14's */
        p[32] = (unsigned char)n;
        p[33] = (unsigned char)(n >> 8);
        /* the items end the VLR's 34 + 6n bytes; anything after them moves */
        size_t at = 34 + 6 * (size_t)c->n_items;
        memmove(p + at + 6, v + at, c->vlr_len - at);
        unsigned char it[6] = {IT_BYTE14, 0, (unsigned char)nl, (unsigned char)(nl >> 8), (unsigned char)version,
                               (unsigned char)(version >> 8)};
        memcpy(p + at, it, 6);
    }
    *out = p;
    return HD_OK;
}

static int encode_table(const hd__laz_chunks_t *c, const uint64_t *bytes, hd__enc_t *e) {
    uint32_t *counts = hd__malloc_array(c->n_chunks + 1, sizeof *counts);
    if (!counts) return HD_ENOMEM;
    for (size_t k = 0; k < c->n_chunks; k++) counts[k] = (uint32_t)(c->first[k + 1] - c->first[k]);
    int rc = hd__laz_table_encode(c->chunk_size == 0 || c->chunk_size == 0xFFFFFFFFu, c->n_chunks, counts, bytes, e);
    free(counts);
    return rc;
}

/* One chunk's outcome of encode_chunk: its new layers, or its failure. */
typedef struct {
    unsigned char *layers; /* the new layers, back to back */
    size_t layers_size;
    int rc;                /* HD_OK or the failure ... */
    hd_error_t err;        /* ... and its message */
} chunk_out_t;

typedef struct {
    hd__writer_t *w;
    hd__las_plan_t pl;
    hd__las_header_t h;
    hd__laz_chunks_t c;
    hd__read_t r;
    hd__sink_t sink;
    size_t nl;              /* the new layers: 8 a field */
    chunk_out_t *out;       /* per chunk */
    uint32_t *sizes;        /* nl per chunk */
    unsigned char *scratch; /* 4 * nl bytes, for write_chunk */
    uint64_t *bytes;        /* each chunk's new byte size */
    int v4;                 /* the BYTE14 item's version is 4 (else 3) */
} lazw_t;

/* Chunk `task`'s new layers (a task of hd__parallel_for: every chunk has
 * its own encoders, models and error). */
static void encode_chunk(void *ctx, size_t k, int worker) {
    (void)worker;
    lazw_t *z = ctx;
    size_t n = (size_t)(z->c.first[k + 1] - z->c.first[k]);
    chunk_out_t *out = &z->out[k];
    hd_error_t *err = &out->err;
    hd__read_t r = z->r;
    r.err = err;
    size_t nl = z->nl;
    unsigned char *chan = malloc(n + 1), *item = malloc(nl);
    int *changed = hd__malloc_array(nl, sizeof *changed);
    hd__enc_t *enc = hd__malloc_array(nl, sizeof *enc);
    for (size_t b = 0; enc && b < nl; b++) hd__enc_init(&enc[b]);
    int rc = chan && item && changed && enc ? HD_OK : hd__err(err, HD_ENOMEM, "out of memory");
    if (rc == HD_OK) {
        memset(chan, 0, n);
        if (n > 1) rc = hd__laz_chunk_channels(&r, &z->h, &z->c, k, chan);
        else chan[0] = (z->w->in->data[z->c.start[k] + 15] >> 4) & 3;
    }
    if (rc == HD_OK &&
        encode_bytes(z->w, (size_t)z->c.first[k], n, chan, z->v4, enc, z->sizes + nl * k, item, changed))
        rc = hd__err(err, HD_ENOMEM, "out of memory");
    uint64_t add = 0;
    for (size_t b = 0; rc == HD_OK && b < nl; b++) add += z->sizes[nl * k + b];
    z->bytes[k] = z->c.start[k + 1] - z->c.start[k] + nl + 4 * nl + add;
    if (rc == HD_OK && z->bytes[k] > 0xFFFFFFFFu)
        rc = hd__err(err, HD_EUNSUPPORTED, "%s: chunk %zu would exceed 4 GiB", z->w->in->name, k + 1);
    if (rc == HD_OK && add && !(out->layers = malloc((size_t)add))) rc = hd__err(err, HD_ENOMEM, "out of memory");
    for (size_t b = 0, at = 0; b < nl && rc == HD_OK; b++) {
        if (z->sizes[nl * k + b]) memcpy(out->layers + at, enc[b].buf, z->sizes[nl * k + b]);
        at += z->sizes[nl * k + b];
    }
    out->layers_size = (size_t)add;
    for (size_t b = 0; enc && b < nl; b++) hd__enc_free(&enc[b]);
    free(enc);
    free(changed);
    free(item);
    free(chan);
    out->rc = rc;
}

/* Encode every chunk's new layers, in parallel (first pass: the sizes are
 * needed before anything after the header is written); the first failing
 * chunk in file order is the error, kept whole (its offset too). */
static int encode_chunks(lazw_t *z) {
    size_t nc = z->c.n_chunks;
    z->out = hd__calloc_array(nc + 1, sizeof *z->out);
    z->sizes = hd__calloc_array(nc + 1, z->nl * sizeof *z->sizes);
    z->bytes = hd__calloc_array(nc + 1, sizeof *z->bytes);
    z->scratch = malloc(4 * z->nl);
    if (!z->out || !z->sizes || !z->bytes || !z->scratch)
        return hd__err(z->w->err, HD_ENOMEM, "out of memory");
    hd__parallel_for(hd__thread_count(z->w->ropt->threads, nc), nc, encode_chunk, z);
    for (size_t k = 0; k < nc; k++)
        if (z->out[k].rc) {
            if (z->w->err) *z->w->err = z->out[k].err;
            return z->out[k].rc;
        }
    return HD_OK;
}

/* One chunk: first point raw and its value, the count, the old sizes and
 * the new ones, the old layers and the new ones. */
static void write_chunk(lazw_t *z, size_t k) {
    hd__writer_t *w = z->w;
    const unsigned char *b = w->in->data + z->c.start[k];
    size_t nb = (size_t)(z->c.start[k + 1] - z->c.start[k]), rec = z->pl.rec, head = rec + 4 + 4 * (size_t)z->c.n_layers;
    size_t nl = z->nl;
    unsigned char *s = z->scratch; /* 4 * nl bytes */
    hd__w_put(w, b, rec);
    hd__w_values(w, (size_t)z->c.first[k], 0, s);
    hd__w_put(w, s, nl);
    hd__w_put(w, b + rec, head - rec);
    for (size_t i = 0; i < nl; i++)
        for (int q = 0; q < 4; q++) s[4 * i + (size_t)q] = (unsigned char)(z->sizes[nl * k + i] >> (8 * q));
    hd__w_put(w, s, 4 * nl);
    hd__w_put(w, b + head, nb - head);
    hd__w_put(w, z->out[k].layers, z->out[k].layers_size);
}

static int write_layered(lazw_t *z) {
    hd__writer_t *w = z->w;
    unsigned char *vlr = NULL;
    size_t vlr_len = 0;
    hd__enc_t table;
    hd__enc_init(&table);
    int rc = encode_chunks(z);
    if (rc == HD_OK) rc = new_vlr(w, &z->c, &vlr, &vlr_len);
    if (rc == HD_OK && (rc = encode_table(&z->c, z->bytes, &table))) rc = hd__err(w->err, rc, "out of memory");
    size_t nc = z->c.n_chunks, gap = z->c.table - (size_t)z->c.start[nc]; /* bytes between the last chunk and the table */
    uint64_t chunks = 0, new_offset = 0, *new_start = hd__malloc_array(nc + 1, sizeof *new_start);
    unsigned char *copc_info = NULL, *copc_hier = NULL;
    if (rc == HD_OK && !new_start) rc = hd__err(w->err, HD_ENOMEM, "out of memory");
    if (rc == HD_OK) {
        z->pl.vlr_added += vlr_len - z->c.vlr_len;
        new_offset = z->pl.offset + z->pl.vlr_added;
        for (size_t k = 0; k < nc; k++) {
            new_start[k] = new_offset + 8 + chunks;
            chunks += z->bytes[k];
        }
        uint64_t table_end = new_offset + 8 + chunks + gap + 8 + table.size; /* the EVLRs move with it */
        rc = hd__copc_move(w, &z->pl, &z->c, new_start, z->bytes, NULL, table_end - z->c.table_end, &copc_info,
                           &copc_hier);
    }
    if (rc == HD_OK) {
        uint64_t table_bytes = 8 + table.size, points = 8 + chunks + gap + table_bytes;
        z->pl.end = z->c.table_end;
        hd__las_write_head(w, &z->pl, w->n, NULL, NULL, points, vlr, z->c.vlr_at, vlr_len);
        unsigned char t[8];
        hd__st_u64(t, new_offset + 8 + chunks + gap);
        hd__w_put(w, t, 8);
        for (size_t k = 0; k < nc && !w->werr; k++) write_chunk(z, k);
        hd__w_put(w, w->in->data + z->c.start[nc], gap);
        unsigned char head[8] = {0, 0, 0, 0, (unsigned char)nc, (unsigned char)(nc >> 8), (unsigned char)(nc >> 16),
                                 (unsigned char)(nc >> 24)};
        hd__w_put(w, head, 8);
        hd__w_put(w, table.buf, table.size);
        hd__las_put_tail(w, &z->pl, z->c.table_end); /* extended VLRs (COPC's hierarchy moved) */
        w->written = w->n;
    }
    free(new_start);
    free(copc_info);
    free(copc_hier);
    hd__enc_free(&table);
    free(vlr);
    return rc;
}

/* Everything z owns (what it does not hold yet is NULL). */
static void lazw_free(lazw_t *z) {
    for (size_t k = 0; z->out && k < z->c.n_chunks; k++) free(z->out[k].layers);
    hd__laz_chunks_free(&z->c);
    free(z->out);
    free(z->sizes);
    free(z->bytes);
    free(z->scratch);
    hd__sink_free(&z->sink);
}

int hd__write_laz(hd__writer_t *w) {
    lazw_t z;
    memset(&z, 0, sizeof z);
    z.w = w;
    z.nl = 8 * w->nf;
    int rc = hd__las_plan(w, &z.pl);
    if (rc) return rc;
    if (!z.pl.add && w->keep == HD_KEEP_ALL) { /* no field, every point: the file as it is */
        hd__w_put(w, w->in->data, w->in->size);
        w->written = w->n;
        return HD_OK;
    }
    hd__las_header_of(w, &z.pl, &z.h);
    hd__sink_init(&z.sink, HD_FLOAT64);
    hd__read_t r = {w->in, w->ropt, 1, &z.sink, NULL, 0, w->err, 0, 0, 0};
    z.r = r;
    rc = hd__laz_chunks(&z.r, &z.h, &z.c);
    if (rc == HD_OK && z.c.layered) rc = hd__copc_plan(w, &z.pl, &z.c);
    if (rc == HD_OK && (!z.c.layered || w->keep != HD_KEEP_ALL)) { /* a layered subset: every point encoded again (laz14.c) */
        if (!z.c.layered) hd__copc_drop(&z.pl); /* COPC is layered: plain LAZ (write_copc.c) */
        rc = hd__write_laz_pointwise(w, &z.pl, &z.h, &z.c, &z.r);
        lazw_free(&z);
        return rc;
    }
    if (rc == HD_OK) /* the BYTE14 item's version: the existing one's, or POINT14's for a new one */
        z.v4 = hd__ld_u16(w->in->data + z.c.vlr_at + 34 + 6 * (size_t)(z.c.type[z.c.n_items - 1] == IT_BYTE14 ? z.c.n_items - 1 : 0) + 4,
                          0) == 4;
    if (rc == HD_OK && z.pl.count == 0)
        rc = hd__err(w->err, HD_EUNSUPPORTED, "%s: a LAZ file without points takes no field", w->in->name);
    if (rc == HD_OK && z.pl.count != w->n)
        rc = hd__err(w->err, HD_EINVAL, "%s: %zu values for %llu points", w->in->name, w->n, (unsigned long long)z.pl.count);
    if (rc == HD_OK) rc = write_layered(&z);
    lazw_free(&z);
    return rc;
}
