/*
 * laz14.c -- layered LAZ (LASzip compressor 3: POINT14, RGB14, RGBNIR14,
 * WAVEPACKET14 and BYTE14 items, versions 3 and 4), every field, decoded and encoded
 * by one description of the format (written from LASzip's published
 * description of its v3/v4 item coders: facts, not code).
 *
 * One code path serves both directions: each coding step is "the symbol
 * (or integer) v with model m in layer L", which the encoder writes (v
 * computed from the record being encoded) and the decoder reads (v
 * returned); the state the models and predictions depend on is then
 * updated from the value coded, identically in both.  The encoder checks
 * after every point that the state it reached is the record it was given,
 * so a record that would not decode back to itself is an error, never a
 * silently different file.
 *
 * A chunk: its first record raw, u32 point count, one u32 byte size per
 * layer, the layers.  POINT14 has nine layers: (0) the changed-values
 * symbol, scanner channel, return counts, x and y; (1) z; (2)
 * classification; (3) flags; (4) intensity; (5) scan angle; (6) user data;
 * (7) point source; (8) GPS time.  RGB14 has one, RGBNIR14 two (RGB, NIR),
 * WAVEPACKET14 one, BYTE14 one per byte.  A layer of size 0 means its field never changes
 * within the chunk: the decoder keeps the last value.  The encoder always
 * writes layers 0 and 1 and drops any other whose values never change.
 *
 * Per scanner channel (0-3) each item has its own models and last values,
 * created when the channel first appears in the chunk, from the last values
 * of the channel the stream was in.  Per point of POINT14, with the
 * channel's last record and whether its GPS time changed:
 *  - a symbol of 128 (model chosen by the last point's first/last return
 *    and GPS change): bit 6 the channel changes, 5 point source, 4 GPS
 *    time, 3 scan angle, 2 number of returns change; bits 0-1 the return
 *    number is the same, +1, -1 (mod 16), or other;
 *  - a new channel as (channel - current - 1) mod 4, a symbol of 3; then
 *    the new channel's last record is the reference;
 *  - a new number of returns by a model chosen by the last one; an other
 *    return number by a model of the last return number (GPS changed) or
 *    as (r - last - 2) mod 16, a symbol of 13 (GPS same);
 *  - dx, dy against the median of the last five of return map context m
 *    (number_return_map_6ctx) doubled by the GPS change, contexts from
 *    n == 1 and dx's k; z against the last z of return level l;
 *  - classification by a model of the last classification's low 5 bits and
 *    whether the point is a single return; flags (edge, scan direction,
 *    classification flags: 6 bits) by a model of the last flags; intensity
 *    against the last of (first/last return, GPS change); scan angle (when
 *    changed) against the last, context GPS change; user data by a model of
 *    the last user data / 4; point source (when changed) against the last;
 *    GPS time (when changed) as LASzip's four sequences of differences
 *    (below).
 * RGB14 and RGBNIR14 code colours as RGB12 v2 does (which bytes changed,
 * green and blue from red's change), NIR's two bytes by their change;
 * WAVEPACKET14 as wave14() says; BYTE14 each byte as its difference to the
 * last.  Version 3 of these
 * items, at a switch to a channel already seen in the chunk, predicts the
 * switching point from (and updates) the last values of the channel it
 * comes from; version 4 uses the channel's own.
 */
#include "laz14.h"

#include "io.h"

#include <stdio.h>
#include <stdlib.h>

#define NL_MAX (9 + 2 + 65535) /* the most layers a record can have */

typedef struct {
    int on;      /* coded: always when encoding; when decoding, it has bytes */
    int changed; /* encoding: a value differed from the last */
    size_t size; /* decoding: its bytes */
    hd__dec_t d;
    hd__enc_t e;
} layer_t;

/* POINT14, one scanner channel. */
typedef struct {
    int used, gps_change;
    unsigned char last[30];
    hd__p14_models_t m; /* what the ordinary reader decodes too */
    hd__symmodel_t gmulti, gzero;
    hd__symmodel_t *cls[64], *flags[64], *user[64];
    hd__intcoder_t inten, scan, psid, gic;
    int32_t last_z[8];
    uint16_t last_int[8];
    uint64_t gt[4];
    int32_t gdiff[4];
    int gext[4];
    unsigned glast, gnext;
} ch_t;

/* RGB14 / RGBNIR14, one channel. */
typedef struct {
    int used;
    unsigned char last[8];
    hd__symmodel_t sym, diff[6], nsym, ndiff[2];
} rgbc_t;

/* BYTE14, one channel: a model per byte, created at its first use (a new
 * model's state is the same whenever it is created). */
typedef struct {
    int used;
    unsigned char *last;
    hd__symmodel_t **m;
} bytc_t;

/* WAVEPACKET14, one channel. */
typedef struct {
    int used;
    unsigned char last[29];
    hd__symmodel_t index, odiff[4];
    hd__intcoder_t ioff, isize, iret, ixyz;
    unsigned sym_last;
    int32_t last_diff;
} wavec_t;

typedef struct {
    int enc, oom;
    const hd__laz14_items_t *it;
    layer_t *L;
    unsigned nl;
    ch_t *ch; /* 4 */
    unsigned cur;
    /* RGB14 / RGBNIR14 */
    int has_rgb, nir, rgb_v4;
    size_t rgb_off;
    unsigned rgb_layer, rgb_cur;
    rgbc_t rgb[4];
    /* WAVEPACKET14 */
    int has_wave, wave_v4;
    size_t wave_off;
    unsigned wave_layer, wave_cur;
    wavec_t wave[4];
    /* BYTE14 */
    int has_bytes, byt_v4;
    size_t byt_off, nb;
    unsigned byt_layer, byt_cur;
    bytc_t byt[4];
} c14_t;

/* ---- the two directions of one coding step ------------------------------- */
static uint32_t csym(const c14_t *s, layer_t *L, hd__symmodel_t *m, uint32_t v) {
    if (s->enc) {
        hd__enc_symbol(&L->e, m, v);
        return v;
    }
    return hd__dec_symbol(&L->d, m);
}
static int32_t cint(const c14_t *s, layer_t *L, hd__intcoder_t *ic, int32_t pred, int32_t v, uint32_t ctx) {
    if (s->enc) {
        hd__ic_encode(ic, &L->e, pred, v, ctx);
        return v;
    }
    return hd__ic_decode(ic, &L->d, pred, ctx);
}
/* x when encoding (a value of the record being encoded), else 0 (the
 * decoder's output is not read before it is written). */
#define E(x) (s->enc ? (x) : 0)

static hd__symmodel_t *lazy(c14_t *s, hd__symmodel_t **slot, uint32_t n) {
    if (!*slot) {
        hd__symmodel_t *m = malloc(sizeof *m);
        if (!m || hd__symmodel_new(m, n)) {
            free(m);
            s->oom = 1;
            return NULL;
        }
        *slot = m;
    }
    return *slot;
}

static uint16_t u16(const unsigned char *p) { return (uint16_t)(p[0] | p[1] << 8); }
static int32_t i32(const unsigned char *p) { return (int32_t)hd__ld_u32(p, 0); }
static uint64_t u64(const unsigned char *p) { return hd__ld_u64(p, 0); }
static void st16(unsigned char *p, unsigned v) {
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
}
static void st32(unsigned char *p, uint32_t v) {
    for (int b = 0; b < 4; b++) p[b] = (unsigned char)(v >> (8 * b));
}
static void st64(unsigned char *p, uint64_t v) {
    for (int b = 0; b < 8; b++) p[b] = (unsigned char)(v >> (8 * b));
}

/* ---- POINT14 -------------------------------------------------------------- */
typedef hd__p14_models_t p14_t;
static const hd__model_spec_t p14_models[] = {
    HD__SYMS(p14_t, changed, 8, 128), HD__SYM(p14_t, scanner, 3), HD__SYM(p14_t, rn_same, 13),
    HD__IC(p14_t, dx, 32, 2),         HD__IC(p14_t, dy, 32, 22),  HD__IC(p14_t, dz, 32, 20)};
/* A channel's models besides POINT14's x, y, z (p14_models). */
static const hd__model_spec_t ch_models[] = {
    HD__SYM(ch_t, gmulti, 515), HD__SYM(ch_t, gzero, 5),   HD__IC(ch_t, inten, 16, 4),
    HD__IC(ch_t, scan, 16, 2),  HD__IC(ch_t, psid, 16, 1), HD__IC(ch_t, gic, 32, 9)};

int hd__p14_models_new(hd__p14_models_t *m) {
    for (int i = 0; i < 12; i++) {
        hd__median5_init(&m->mx[i]);
        hd__median5_init(&m->my[i]);
    }
    return HD__MODELS_NEW(m, p14_models);
}
void hd__p14_models_free(hd__p14_models_t *m) {
    HD__MODELS_FREE(m, p14_models);
    hd__lazy_models_free(m->nret, 16);
    hd__lazy_models_free(m->rnum, 16);
}

static void ch_free(ch_t *c) {
    hd__p14_models_free(&c->m);
    HD__MODELS_FREE(c, ch_models);
    hd__lazy_models_free(c->cls, 64);
    hd__lazy_models_free(c->flags, 64);
    hd__lazy_models_free(c->user, 64);
}

/* Channel c's models, started from the record `from` (the chunk's first,
 * or the last of the channel the stream was in). */
static int ch_start(ch_t *c, const unsigned char *from) {
    int rc = hd__p14_models_new(&c->m);
    rc = rc ? rc : HD__MODELS_NEW(c, ch_models);
    c->used = 1; /* freed by ch_free even when a step failed */
    if (rc) return rc;
    memcpy(c->last, from, 30);
    c->gps_change = 0;
    for (int i = 0; i < 8; i++) {
        c->last_z[i] = i32(from + 8);
        c->last_int[i] = u16(from + 12);
    }
    memset(c->gdiff, 0, sizeof c->gdiff);
    memset(c->gext, 0, sizeof c->gext);
    c->gt[0] = u64(from + 22);
    c->gt[1] = c->gt[2] = c->gt[3] = 0;
    c->glast = c->gnext = 0;
    return HD_OK;
}

static int32_t times(int32_t m, int32_t v) { return (int32_t)((uint32_t)m * (uint32_t)v); }

/* A new sequence: the high 32 bits against the current sequence's, the low
 * 32 raw. */
static void gps_full(c14_t *s, ch_t *c, layer_t *L, uint64_t T) {
    unsigned cur = c->glast;
    c->gnext = (c->gnext + 1) & 3;
    uint32_t hi = (uint32_t)cint(s, L, &c->gic, (int32_t)(uint32_t)(c->gt[cur] >> 32), E((int32_t)(uint32_t)(T >> 32)), 8);
    uint32_t lo;
    if (s->enc) {
        hd__enc_raw(&L->e, 32, (uint32_t)T);
        lo = (uint32_t)T;
    } else {
        lo = hd__dec_raw(&L->d, 32);
    }
    c->gt[c->gnext] = (uint64_t)hi << 32 | lo;
    c->glast = c->gnext;
    c->gdiff[c->glast] = 0;
    c->gext[c->glast] = 0;
}

/* The difference d coded against the sequence's last difference, with the
 * multiplier symbol multi (1..514, not 511 or above); updates the state. */
static void gps_multi(c14_t *s, ch_t *c, layer_t *L, uint32_t multi, int32_t d) {
    unsigned q = c->glast;
    int32_t last = c->gdiff[q], diff;
    int extreme = 0;
    if (multi == 1) {
        diff = cint(s, L, &c->gic, last, d, 1);
        c->gext[q] = 0;
    } else if (multi == 0) {
        diff = cint(s, L, &c->gic, 0, d, 7);
        extreme = 1;
    } else if (multi < 500) {
        diff = cint(s, L, &c->gic, times((int32_t)multi, last), d, multi < 10 ? 2 : 3);
    } else if (multi == 500) {
        diff = cint(s, L, &c->gic, times(500, last), d, 4);
        extreme = 1;
    } else {
        int32_t mm = 500 - (int32_t)multi; /* -1 .. -10 */
        extreme = mm <= -10;
        diff = cint(s, L, &c->gic, times(extreme ? -10 : mm, last), d, extreme ? 6 : 5);
    }
    if (extreme && ++c->gext[q] > 3) {
        c->gdiff[q] = diff;
        c->gext[q] = 0;
    }
    c->gt[q] += (uint64_t)(int64_t)diff;
}

/* T's difference to sequence q: 1 and *d when it fits 32 bits. */
static int fits(const ch_t *c, unsigned q, uint64_t T, int32_t *d) {
    int64_t diff = (int64_t)(T - c->gt[q]);
    *d = (int32_t)diff;
    return diff >= INT32_MIN && diff <= INT32_MAX;
}

/* The multiplier symbol of difference d against the last difference
 * (LASzip's choice: the ratio rounded, capped to 500 and -10). */
static uint32_t gps_choose(int32_t d, int32_t last) {
    float f = (float)d / (float)last;
    if (f > 600.0f) f = 600.0f; /* the caps keep the rounding defined */
    if (f < -20.0f) f = -20.0f;
    int32_t m = f >= 0 ? (int32_t)(f + 0.5f) : (int32_t)(f - 0.5f);
    if (m >= 500) return 500;
    if (m <= -10) return 510;
    if (m < 0) return (uint32_t)(500 - m);
    return (uint32_t)m;
}

/* One changed GPS time T (encoding) or the next (decoding): 0, or -1 when
 * a stream switches sequence more than a valid one can (three times). */
static int gps_code(c14_t *s, ch_t *c, layer_t *L, uint64_t T) {
    for (int round = 0; round < 4; round++) {
        unsigned q = c->glast;
        int32_t d = 0;
        int ok = s->enc && fits(c, q, T, &d);
        unsigned other = 0;
        for (unsigned i = 1; s->enc && !ok && i < 4 && !other; i++)
            if (fits(c, (q + i) & 3, T, &d)) other = i;
        if (c->gdiff[q] == 0) {
            uint32_t sym = csym(s, L, &c->gzero, E(ok ? 0 : other ? other + 1 : 1));
            if (sym == 0) {
                c->gdiff[q] = cint(s, L, &c->gic, 0, d, 0);
                c->gt[q] += (uint64_t)(int64_t)c->gdiff[q];
                c->gext[q] = 0;
                return 0;
            }
            if (sym == 1) {
                gps_full(s, c, L, T);
                return 0;
            }
            c->glast = (q + sym - 1) & 3;
            continue;
        }
        uint32_t sym = csym(s, L, &c->gmulti, E(ok ? gps_choose(d, c->gdiff[q]) : other ? 511 + other : 511));
        if (sym < 511) {
            gps_multi(s, c, L, sym, d);
            return 0;
        }
        if (sym == 511) {
            gps_full(s, c, L, T);
            return 0;
        }
        c->glast = (q + sym - 511) & 3;
    }
    return -1;
}

/* The changed-values symbol (and a new scanner channel): the encoder's
 * from rec against the last record of rec's channel; s->cur is then the
 * point's channel.  HD_OK or HD_ENOMEM. */
static int p14_changed(c14_t *s, const unsigned char *rec, uint32_t *out) {
    ch_t *c = &s->ch[s->cur];
    const unsigned char *last = c->last;
    unsigned lr = last[14] & 15, ln = last[14] >> 4;
    unsigned lpr = (lr == 1) + 2 * (lr >= ln) + 4 * (unsigned)c->gps_change;
    uint32_t cv = 0;
    unsigned chan = s->cur;
    if (s->enc) {
        chan = (rec[15] >> 4) & 3;
        const unsigned char *ref = chan != s->cur && s->ch[chan].used ? s->ch[chan].last : last;
        unsigned n = rec[14] >> 4, r = rec[14] & 15, rn = ref[14] >> 4, rr = ref[14] & 15;
        cv = (uint32_t)(chan != s->cur) << 6 | (uint32_t)(u16(rec + 20) != u16(ref + 20)) << 5 |
             (uint32_t)(u64(rec + 22) != u64(ref + 22)) << 4 | (uint32_t)(u16(rec + 18) != u16(ref + 18)) << 3 |
             (uint32_t)(n != rn) << 2;
        if (r != rr) cv |= r == ((rr + 1) & 15) ? 1u : r == ((rr + 15) & 15) ? 2u : 3u;
    }
    *out = cv = csym(s, &s->L[0], &c->m.changed[lpr], cv);
    if (!(cv & 64)) return HD_OK;
    unsigned d = csym(s, &s->L[0], &c->m.scanner, E((chan - s->cur + 3) & 3));
    chan = (s->cur + d + 1) & 3;
    if (!s->ch[chan].used && ch_start(&s->ch[chan], last)) return HD_ENOMEM;
    s->cur = chan;
    s->ch[chan].last[15] = (unsigned char)((s->ch[chan].last[15] & 0xCF) | chan << 4);
    return HD_OK;
}

/* The number of returns and the return number into c->last.  HD_OK or
 * HD_ENOMEM. */
static int p14_returns(c14_t *s, ch_t *c, const unsigned char *rec, uint32_t cv) {
    unsigned char *last = c->last;
    unsigned ln = last[14] >> 4, lr = last[14] & 15, n = ln, r = lr;
    hd__symmodel_t *m;
    if (cv & 4) {
        if (!(m = lazy(s, &c->m.nret[ln], 16))) return HD_ENOMEM;
        n = csym(s, &s->L[0], m, E(rec[14] >> 4));
    }
    if ((cv & 3) == 1) r = (lr + 1) & 15;
    if ((cv & 3) == 2) r = (lr + 15) & 15;
    if ((cv & 3) == 3 && (cv & 16)) {
        if (!(m = lazy(s, &c->m.rnum[lr], 16))) return HD_ENOMEM;
        r = csym(s, &s->L[0], m, E(rec[14] & 15));
    } else if ((cv & 3) == 3) {
        r = (lr + csym(s, &s->L[0], &c->m.rn_same, E(((rec[14] & 15) - lr - 2) & 15)) + 2) & 15;
    }
    last[14] = (unsigned char)(r | n << 4);
    return HD_OK;
}

/* x and y (layer 0), z (layer 1, when it has bytes) into c->last. */
static void p14_xyz(c14_t *s, ch_t *c, const unsigned char *rec, unsigned gps) {
    unsigned char *last = c->last;
    unsigned n = last[14] >> 4, r = last[14] & 15;
    unsigned mi = (unsigned)hd__laz_rmap14[n][r] << 1 | gps, l = hd__laz_level(n, r);
    uint32_t X = hd__ld_u32(last, 0), Y = hd__ld_u32(last + 4, 0);
    int32_t dx = cint(s, &s->L[0], &c->m.dx, c->m.mx[mi].v[2], E((int32_t)(hd__ld_u32(rec, 0) - X)), n == 1);
    hd__median5_add(&c->m.mx[mi], dx);
    int32_t dy = cint(s, &s->L[0], &c->m.dy, c->m.my[mi].v[2], E((int32_t)(hd__ld_u32(rec + 4, 0) - Y)),
                      (n == 1) + hd__laz_kctx(c->m.dx.k, 20));
    hd__median5_add(&c->m.my[mi], dy);
    st32(last, X + (uint32_t)dx);
    st32(last + 4, Y + (uint32_t)dy);
    if (s->L[1].on) {
        int32_t Z = cint(s, &s->L[1], &c->m.dz, c->last_z[l], E(i32(rec + 8)), (n == 1) + hd__laz_kctx((c->m.dx.k + c->m.dy.k) / 2, 18));
        c->last_z[l] = Z;
        st32(last + 8, (uint32_t)Z);
    }
}

/* A byte field of layer k by a model of slots[ctx] (n symbols) into *v;
 * `now` the encoder's value.  HD_OK or HD_ENOMEM. */
static int p14_byte(c14_t *s, unsigned k, hd__symmodel_t **slots, unsigned ctx, uint32_t n, unsigned now, unsigned *v) {
    hd__symmodel_t *m;
    if (!s->L[k].on) return HD_OK;
    if (!(m = lazy(s, &slots[ctx], n))) return HD_ENOMEM;
    unsigned was = *v;
    *v = csym(s, &s->L[k], m, now);
    s->L[k].changed |= *v != was;
    return HD_OK;
}

/* Classification, flags, intensity, scan angle, user data, point source
 * into c->last (layers 2-7, those with bytes).  HD_OK or HD_ENOMEM. */
static int p14_attributes(c14_t *s, ch_t *c, const unsigned char *rec, uint32_t cv) {
    unsigned char *last = c->last;
    unsigned n = last[14] >> 4, r = last[14] & 15, gps = (cv >> 4) & 1, cpr = (r == 1) + 2 * (r >= n);
    unsigned cls = last[16], f = ((last[15] >> 2) & 0x30) | (last[15] & 15), ud = last[17];
    int rc = p14_byte(s, 2, c->cls, ((cls & 31) << 1) + (cpr == 3), 256, E(rec[16]), &cls);
    rc = rc ? rc : p14_byte(s, 3, c->flags, f, 64, E(((rec[15] >> 2) & 0x30u) | (rec[15] & 15u)), &f);
    rc = rc ? rc : p14_byte(s, 6, c->user, ud / 4, 256, E(rec[17]), &ud);
    if (rc) return rc;
    last[15] = (unsigned char)((f & 15) | (f & 0x30) << 2 | s->cur << 4);
    last[16] = (unsigned char)cls;
    last[17] = (unsigned char)ud;
    if (s->L[4].on) {
        unsigned q = cpr << 1 | gps, inten = (uint16_t)cint(s, &s->L[4], &c->inten, c->last_int[q], E(u16(rec + 12)), cpr);
        c->last_int[q] = (uint16_t)inten;
        s->L[4].changed |= inten != u16(last + 12);
        st16(last + 12, inten);
    }
    if (s->L[5].on && (cv & 8)) {
        st16(last + 18, (uint16_t)cint(s, &s->L[5], &c->scan, u16(last + 18), E(u16(rec + 18)), gps));
        s->L[5].changed = 1;
    }
    if (s->L[7].on && (cv & 32)) {
        st16(last + 20, (uint16_t)cint(s, &s->L[7], &c->psid, u16(last + 20), E(u16(rec + 20)), 0));
        s->L[7].changed = 1;
    }
    return HD_OK;
}

/* The POINT14 record of the next point into rec (decoding) or from it
 * (encoding), its channel's last record updated field by field (each
 * field's context depends on its own last value and the point's returns
 * and GPS change only).  HD_OK, HD_ENOMEM, HD_EFORMAT (GPS sequences),
 * HD_EINVAL (encoding: the record would not decode back to itself). */
static int point14(c14_t *s, unsigned char *rec) {
    uint32_t cv;
    int rc = p14_changed(s, rec, &cv);
    ch_t *c = &s->ch[s->cur];
    rc = rc ? rc : p14_returns(s, c, rec, cv);
    if (rc) return rc;
    p14_xyz(s, c, rec, (cv >> 4) & 1);
    if ((rc = p14_attributes(s, c, rec, cv))) return rc;
    if (s->L[8].on && (cv & 16)) {
        if (gps_code(s, c, &s->L[8], E(u64(rec + 22)))) return HD_EFORMAT;
        st64(c->last + 22, c->gt[c->glast]);
        s->L[8].changed = 1;
    }
    c->gps_change = (cv >> 4) & 1;
    if (!s->enc) memcpy(rec, c->last, 30);
    else if (memcmp(rec, c->last, 30) != 0) return HD_EINVAL;
    return HD_OK;
}

/* ---- RGB14, RGBNIR14 ------------------------------------------------------ */
static const hd__model_spec_t rgbc_models[] = {
    HD__SYM(rgbc_t, sym, 128), HD__SYMS(rgbc_t, diff, 6, 256), HD__SYM(rgbc_t, nsym, 4), HD__SYMS(rgbc_t, ndiff, 2, 256)};
static int rgbc_start(rgbc_t *c, const unsigned char *from) {
    int rc = HD__MODELS_NEW(c, rgbc_models);
    c->used = 1;
    memcpy(c->last, from, 8);
    return rc;
}
static void rgbc_free(rgbc_t *c) { HD__MODELS_FREE(c, rgbc_models); }

static unsigned clamp8(int v) { return v < 0 ? 0u : v > 255 ? 255u : (unsigned)v; }

/* A byte that is `was` or, when `bit` is set, pred + the symbol of model
 * m (the encoder's symbol: now - pred). */
static unsigned cbyte(const c14_t *s, layer_t *L, hd__symmodel_t *m, int bit, unsigned pred, unsigned now, unsigned was) {
    if (!bit) return was;
    return (csym(s, L, m, E((now - pred) & 255)) + pred) & 255;
}

/* What an item (RGB14, RGBNIR14, WAVEPACKET14, BYTE14) predicts the point
 * from when the point's channel is not the item's (*item_cur, moved to
 * it; see the top): the last values of the channel it comes from (CH_SAME),
 * the point's channel's own (CH_OWN), or these started from those (CH_FIRST:
 * the channel is not `used` yet).  v4: the item's version is 4. */
typedef enum { CH_SAME, CH_FIRST, CH_OWN } item_switch_t;
static item_switch_t item_switch(const c14_t *s, unsigned *item_cur, int used, int v4) {
    if (s->cur == *item_cur) return CH_SAME;
    *item_cur = s->cur;
    return !used ? CH_FIRST : v4 ? CH_OWN : CH_SAME;
}

/* The last values to predict from (item_switch); NULL when a channel's
 * models could not be made. */
static unsigned char *rgb_last(c14_t *s) {
    unsigned char *lp = s->rgb[s->rgb_cur].last;
    item_switch_t w = item_switch(s, &s->rgb_cur, s->rgb[s->cur].used, s->rgb_v4);
    if (w == CH_FIRST && rgbc_start(&s->rgb[s->cur], lp)) return NULL;
    return w == CH_SAME ? lp : s->rgb[s->cur].last;
}

static int rgb14(c14_t *s, unsigned char *item) {
    unsigned char *lp = rgb_last(s);
    if (!lp) return HD_ENOMEM;
    rgbc_t *c = &s->rgb[s->cur];
    layer_t *L = &s->L[s->rgb_layer];
    unsigned char out[8], *now = item; /* now: the record's bytes (encoding) */
    memcpy(out, lp, 8);
    if (L->on) {
        uint32_t sym = 0;
        if (s->enc) {
            for (int b = 0; b < 6; b++) sym |= (uint32_t)(now[b] != lp[b]) << b;
            sym |= (uint32_t)(now[0] != now[2] || now[0] != now[4] || now[1] != now[3] || now[1] != now[5]) << 6;
        }
        sym = csym(s, L, &c->sym, sym);
        out[0] = (unsigned char)cbyte(s, L, &c->diff[0], sym & 1, lp[0], E(now[0]), lp[0]);
        out[1] = (unsigned char)cbyte(s, L, &c->diff[1], sym & 2, lp[1], E(now[1]), lp[1]);
        if (sym & 64) {
            int d = (int)out[0] - lp[0];
            out[2] = (unsigned char)cbyte(s, L, &c->diff[2], sym & 4, clamp8(d + lp[2]), E(now[2]), lp[2]);
            if (sym & 16) {
                d = (d + ((int)out[2] - lp[2])) / 2;
                out[4] = (unsigned char)cbyte(s, L, &c->diff[4], 1, clamp8(d + lp[4]), E(now[4]), lp[4]);
            }
            d = (int)out[1] - lp[1];
            out[3] = (unsigned char)cbyte(s, L, &c->diff[3], sym & 8, clamp8(d + lp[3]), E(now[3]), lp[3]);
            if (sym & 32) {
                d = (d + ((int)out[3] - lp[3])) / 2;
                out[5] = (unsigned char)cbyte(s, L, &c->diff[5], 1, clamp8(d + lp[5]), E(now[5]), lp[5]);
            }
        } else {
            out[2] = out[4] = out[0];
            out[3] = out[5] = out[1];
        }
        memcpy(lp, out, 6);
        L->changed |= sym != 0;
    }
    if (s->nir) {
        layer_t *N = L + 1;
        if (N->on) {
            uint32_t sym = E((uint32_t)(now[6] != lp[6]) | (uint32_t)(now[7] != lp[7]) << 1);
            sym = csym(s, N, &c->nsym, sym);
            out[6] = (unsigned char)cbyte(s, N, &c->ndiff[0], sym & 1, lp[6], E(now[6]), lp[6]);
            out[7] = (unsigned char)cbyte(s, N, &c->ndiff[1], sym & 2, lp[7], E(now[7]), lp[7]);
            lp[6] = out[6];
            lp[7] = out[7];
            N->changed |= sym != 0;
        }
    }
    size_t size = s->nir ? 8 : 6;
    if (!s->enc) memcpy(item, out, size);
    else if (memcmp(item, out, size) != 0) return HD_EINVAL;
    return HD_OK;
}

/* ---- WAVEPACKET14 ---------------------------------------------------------- */
static const hd__model_spec_t wavec_models[] = {
    HD__SYM(wavec_t, index, 256),  HD__SYMS(wavec_t, odiff, 4, 4), HD__IC(wavec_t, ioff, 32, 1),
    HD__IC(wavec_t, isize, 32, 1), HD__IC(wavec_t, iret, 32, 1),   HD__IC(wavec_t, ixyz, 32, 3)};
static int wavec_start(wavec_t *c, const unsigned char *from) {
    int rc = HD__MODELS_NEW(c, wavec_models);
    c->used = 1;
    c->sym_last = 0;
    c->last_diff = 0;
    memcpy(c->last, from, 29);
    return rc;
}
static void wavec_free(wavec_t *c) { HD__MODELS_FREE(c, wavec_models); }

/* A wave packet descriptor (29 bytes: index, u64 offset, u32 size, f32
 * return point, f32 x, y, z, the floats coded as their 32 bits): the
 * index by a symbol of 256; the offset as the last (0), the last plus the
 * last size (1), the last plus a 32-bit difference predicted by the last
 * such difference (2), or its 64 raw bits (3), that choice by a model of
 * the previous choice; the others against the last values. */
static int wave14(c14_t *s, unsigned char *item) {
    unsigned char *lp = s->wave[s->wave_cur].last;
    item_switch_t w = item_switch(s, &s->wave_cur, s->wave[s->cur].used, s->wave_v4);
    if (w == CH_FIRST && wavec_start(&s->wave[s->cur], lp)) return HD_ENOMEM;
    if (w != CH_SAME) lp = s->wave[s->cur].last;
    wavec_t *c = &s->wave[s->cur];
    layer_t *L = &s->L[s->wave_layer];
    unsigned char out[29];
    if (!L->on) { /* never changes in the chunk */
        if (!s->enc) memcpy(item, lp, 29);
        return HD_OK;
    }
    if (s->enc) L->changed |= memcmp(item, lp, 29) != 0;
    out[0] = (unsigned char)csym(s, L, &c->index, E(item[0]));
    uint64_t loff = u64(lp + 1), off = loff;
    uint32_t lsize = hd__ld_u32(lp + 9, 0);
    uint32_t sym = 0;
    int32_t d32 = 0;
    if (s->enc) {
        uint64_t now = u64(item + 1);
        int64_t d = (int64_t)(now - loff);
        d32 = (int32_t)d;
        sym = d != d32 ? 3u : d32 == 0 ? 0u : now == loff + lsize ? 1u : 2u;
    }
    sym = csym(s, L, &c->odiff[c->sym_last], sym);
    c->sym_last = sym;
    if (sym == 1) {
        off = loff + lsize;
    } else if (sym == 2) {
        c->last_diff = cint(s, L, &c->ioff, c->last_diff, d32, 0);
        off = loff + (uint64_t)(int64_t)c->last_diff;
    } else if (sym == 3) {
        uint32_t lo, hi;
        if (s->enc) {
            off = u64(item + 1);
            hd__enc_raw(&L->e, 32, (uint32_t)off);
            hd__enc_raw(&L->e, 32, (uint32_t)(off >> 32));
        } else {
            lo = hd__dec_raw(&L->d, 32);
            hi = hd__dec_raw(&L->d, 32);
            off = (uint64_t)hi << 32 | lo;
        }
    }
    st64(out + 1, off);
    st32(out + 9, (uint32_t)cint(s, L, &c->isize, (int32_t)lsize, E(i32(item + 9)), 0));
    st32(out + 13, (uint32_t)cint(s, L, &c->iret, i32(lp + 13), E(i32(item + 13)), 0));
    for (int k = 0; k < 3; k++)
        st32(out + 17 + 4 * k, (uint32_t)cint(s, L, &c->ixyz, i32(lp + 17 + 4 * k), E(i32(item + 17 + 4 * k)), (uint32_t)k));
    memcpy(lp, out, 29);
    if (!s->enc) memcpy(item, out, 29);
    else if (memcmp(item, out, 29) != 0) return HD_EINVAL;
    return HD_OK;
}

/* ---- BYTE14 --------------------------------------------------------------- */
static int bytc_start(bytc_t *c, const unsigned char *from, size_t nb) {
    c->used = 1;
    c->last = malloc(nb);
    c->m = calloc(nb, sizeof *c->m);
    if (!c->last || !c->m) return HD_ENOMEM;
    memcpy(c->last, from, nb);
    return HD_OK;
}
static void bytc_free(bytc_t *c, size_t nb) {
    if (c->m) hd__lazy_models_free(c->m, nb);
    free(c->m);
    free(c->last);
}

static int byte14(c14_t *s, unsigned char *item) {
    unsigned char *lp = s->byt[s->byt_cur].last;
    item_switch_t w = item_switch(s, &s->byt_cur, s->byt[s->cur].used, s->byt_v4);
    if (w == CH_FIRST && bytc_start(&s->byt[s->cur], lp, s->nb)) return HD_ENOMEM;
    if (w != CH_SAME) lp = s->byt[s->cur].last;
    bytc_t *c = &s->byt[s->cur];
    for (size_t k = 0; k < s->nb; k++) {
        layer_t *L = &s->L[s->byt_layer + k];
        unsigned v = lp[k];
        if (L->on) {
            hd__symmodel_t *m = lazy(s, &c->m[k], 256);
            if (!m) return HD_ENOMEM;
            v = cbyte(s, L, m, 1, lp[k], E(item[k]), lp[k]);
            L->changed |= v != lp[k];
            lp[k] = (unsigned char)v;
        }
        if (!s->enc) item[k] = (unsigned char)v;
        else if (item[k] != v) return HD_EINVAL;
    }
    return HD_OK;
}

/* ---- a chunk -------------------------------------------------------------- */

/* The state for items `it`, records of `rec` bytes, first record `first`:
 * offsets, layer numbers, the first channel's models. */
static int c14_start(c14_t *s, const hd__laz14_items_t *it, const unsigned char *first, int enc) {
    memset(s, 0, sizeof *s);
    s->enc = enc;
    s->it = it;
    size_t off = 0;
    unsigned nl = 0;
    for (unsigned i = 0; i < it->n; i++) {
        unsigned t = it->type[i];
        if (t == HD__LAZ_IT_POINT14) nl += 9;
        if (t == HD__LAZ_IT_RGB14 || t == HD__LAZ_IT_RGBNIR14) {
            s->has_rgb = 1;
            s->nir = t == HD__LAZ_IT_RGBNIR14;
            s->rgb_v4 = it->version[i] == 4;
            s->rgb_off = off;
            s->rgb_layer = nl;
            nl += s->nir ? 2 : 1;
        }
        if (t == HD__LAZ_IT_BYTE14) {
            s->has_bytes = 1;
            s->byt_v4 = it->version[i] == 4;
            s->byt_off = off;
            s->nb = it->size[i];
            s->byt_layer = nl;
            nl += it->size[i];
        }
        if (t == HD__LAZ_IT_WAVE14) {
            s->has_wave = 1;
            s->wave_v4 = it->version[i] == 4;
            s->wave_off = off;
            s->wave_layer = nl++;
        }
        off += it->size[i];
    }
    s->nl = nl;
    s->L = calloc(nl, sizeof *s->L);
    s->ch = calloc(4, sizeof *s->ch);
    if (!s->L || !s->ch) return HD_ENOMEM;
    for (unsigned k = 0; k < nl; k++) hd__enc_init(&s->L[k].e);
    s->cur = s->rgb_cur = s->wave_cur = s->byt_cur = (first[15] >> 4) & 3;
    int rc = ch_start(&s->ch[s->cur], first);
    unsigned char rgb[8] = {0};
    if (rc == HD_OK && s->has_rgb) {
        memcpy(rgb, first + s->rgb_off, s->nir ? 8 : 6);
        rc = rgbc_start(&s->rgb[s->cur], rgb);
    }
    if (rc == HD_OK && s->has_wave) rc = wavec_start(&s->wave[s->cur], first + s->wave_off);
    if (rc == HD_OK && s->has_bytes) rc = bytc_start(&s->byt[s->cur], first + s->byt_off, s->nb);
    return rc;
}

static void c14_free(c14_t *s) {
    for (int c = 0; s->ch && c < 4; c++)
        if (s->ch[c].used) ch_free(&s->ch[c]);
    for (int c = 0; c < 4; c++) {
        if (s->rgb[c].used) rgbc_free(&s->rgb[c]);
        if (s->wave[c].used) wavec_free(&s->wave[c]);
        if (s->byt[c].used) bytc_free(&s->byt[c], s->nb);
    }
    for (unsigned k = 0; s->L && k < s->nl; k++) hd__enc_free(&s->L[k].e);
    free(s->L);
    free(s->ch);
}

/* Every item of the next point, rec its record. */
static int c14_point(c14_t *s, unsigned char *rec) {
    int rc = point14(s, rec);
    if (rc == HD_OK && s->has_rgb) rc = rgb14(s, rec + s->rgb_off);
    if (rc == HD_OK && s->has_wave) rc = wave14(s, rec + s->wave_off);
    if (rc == HD_OK && s->has_bytes) rc = byte14(s, rec + s->byt_off);
    if (s->oom) rc = HD_ENOMEM;
    return rc;
}

static const char *layer_name(const c14_t *s, unsigned k, char buf[32]) {
    static const char *const p14[9] = {"x/y",       "z",         "classification", "flags", "intensity",
                                       "scan angle", "user data", "point source",   "GPS time"};
    if (k < 9) return p14[k];
    if (s->has_rgb && k == s->rgb_layer) return "RGB";
    if (s->has_rgb && s->nir && k == s->rgb_layer + 1) return "NIR";
    if (s->has_wave && k == s->wave_layer) return "wave packet";
    snprintf(buf, 32, "extra byte %u", k - s->byt_layer + 1);
    return buf;
}

/* A chunk's header after its first record: its point count (the table's
 * n), its layer sizes, which fill the chunk exactly; each layer's decoder
 * started.  HD_OK or HD_EFORMAT with msg and *at. */
static int layers_start(c14_t *s, const unsigned char *b, size_t nb, size_t n, size_t rec, char *msg, size_t len,
                        size_t *at) {
    size_t head = rec + 4 + 4 * (size_t)s->nl, pos = head;
    if (nb < head) {
        snprintf(msg, len, "chunk of %zu bytes is shorter than its first point and layer sizes (%zu bytes)", nb, head);
        return HD_EFORMAT;
    }
    if (hd__ld_u32(b + rec, 0) != n) {
        *at = rec;
        snprintf(msg, len, "the chunk says it holds %u points, the chunk table %zu", hd__ld_u32(b + rec, 0), n);
        return HD_EFORMAT;
    }
    for (unsigned k = 0; k < s->nl; k++) {
        size_t sz = hd__ld_u32(b + rec + 4 + 4 * (size_t)k, 0);
        if (sz > nb - pos) {
            *at = rec + 4 + 4 * (size_t)k;
            snprintf(msg, len, "the chunk's layer %u of %u runs past its end", k + 1, s->nl);
            return HD_EFORMAT;
        }
        s->L[k].on = sz > 0 || k == 0; /* x/y is always decoded */
        s->L[k].size = sz;
        hd__dec_init(&s->L[k].d, b + pos, sz);
        pos += sz;
    }
    if (pos != nb) {
        *at = rec + 4;
        snprintf(msg, len, "the chunk's layers fill only %zu of the %zu bytes after its header", pos - head, nb - head);
        return HD_EFORMAT;
    }
    return HD_OK;
}

/* Layer k's decoder ran past its bytes (ends: at the end, too, it must
 * stop exactly at its last byte; see laz.c's stream_end).  HD_OK or
 * HD_EFORMAT with msg and *at. */
static int layer_check(c14_t *s, unsigned k, const unsigned char *b, size_t n, int ends, char *msg, size_t len,
                       size_t *at) {
    const hd__dec_t *d = &s->L[k].d;
    char buf[32];
    if (!ends && d->over <= 4) return HD_OK;
    if (ends && !d->over && d->p == d->end) return HD_OK;
    *at = (size_t)(d->end - b);
    snprintf(msg, len, "the chunk's %s layer %s after its %zu point%s", layer_name(s, k, buf),
             d->over ? "ends before the decoder stops" : "has bytes left", n, n == 1 ? "" : "s");
    return HD_EFORMAT;
}

int hd__laz14_decode(const unsigned char *b, size_t nb, size_t n, size_t rec, const hd__laz14_items_t *it,
                     unsigned char *recs, char *msg, size_t len, size_t *at) {
    c14_t s;
    *at = 0;
    if (nb < rec) {
        snprintf(msg, len, "chunk of %zu bytes is shorter than its first point's %zu bytes", nb, rec);
        return HD_EFORMAT;
    }
    memcpy(recs, b, rec);
    int rc = c14_start(&s, it, b, 0);
    if (rc) snprintf(msg, len, "out of memory");
    else rc = layers_start(&s, b, nb, n, rec, msg, len, at);
    for (size_t i = 1; rc == HD_OK && i < n; i++) {
        rc = c14_point(&s, recs + i * rec);
        if (rc == HD_EFORMAT) snprintf(msg, len, "point %zu: the GPS time switches sequence more than three times", i + 1);
        if (rc == HD_ENOMEM) snprintf(msg, len, "out of memory");
        for (unsigned k = 0; rc == HD_OK && k < s.nl; k++) rc = layer_check(&s, k, b, n, 0, msg, len, at);
    }
    /* every layer with bytes is used up exactly, and so is the x/y layer of
     * a chunk of more than one point */
    for (unsigned k = 0; rc == HD_OK && k < s.nl; k++)
        if (s.L[k].size || (k == 0 && n > 1)) rc = layer_check(&s, k, b, n, 1, msg, len, at);
    c14_free(&s);
    return rc;
}

int hd__laz14_encode(const unsigned char *recs, size_t n, size_t rec, const hd__laz14_items_t *it, hd__enc_t *out) {
    c14_t s;
    int rc = c14_start(&s, it, recs, 1);
    for (unsigned k = 0; k < s.nl; k++) s.L[k].on = 1;
    unsigned char *r = rc == HD_OK ? malloc(rec) : NULL;
    if (rc == HD_OK && !r) rc = HD_ENOMEM;
    for (size_t i = 1; rc == HD_OK && i < n; i++) {
        memcpy(r, recs + i * rec, rec);
        rc = c14_point(&s, r);
    }
    free(r);
    hd__enc_reset(out);
    if (rc == HD_OK) {
        unsigned char u[4];
        st32(u, (uint32_t)n);
        hd__enc_put(out, u, 4);
        for (unsigned k = 0; k < s.nl; k++) {
            layer_t *L = &s.L[k];
            int keep = k < 2 || L->changed; /* x/y and z always; others only when they change */
            if (keep) hd__enc_done(&L->e);
            if (L->e.oom) rc = HD_ENOMEM;
            st32(u, keep ? (uint32_t)L->e.size : 0);
            hd__enc_put(out, u, 4);
        }
        for (unsigned k = 0; k < s.nl; k++)
            if (k < 2 || s.L[k].changed) hd__enc_put(out, s.L[k].e.buf, s.L[k].e.size);
        if (out->oom) rc = HD_ENOMEM;
    }
    c14_free(&s);
    return rc;
}
