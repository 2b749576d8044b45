/*
 * lazcoder.h -- the entropy coder of LASzip: an adaptive range coder with
 * 32-bit registers (Amir Said's FastAC as LASzip adapted it), its bit and
 * symbol models, and LASzip's integer compressor, decoding and encoding.
 * Shared by the LAZ reader (laz.c), the LAZ writer of hd_write_field
 * (write_laz.c) and the tests' LAZ writer; the writers' files are checked
 * by an independent decoder (laz-perf), so a model mistake shared by both
 * sides cannot pass unnoticed.
 *
 * Facts of the format (from the LASzip sources' description, not their
 * code): the interval has a 32-bit length, renormalised a byte at a time
 * whenever it falls below 2^24 (AC_MIN); a decoder starts by reading four
 * bytes big-endian into `value`.  A bit model keeps the probability of 0
 * in 13 bits, a symbol model a cumulative distribution in 15 bits; both
 * recompute it from their counts periodically (every 4 bits at first, the
 * period growing by 5/4 up to 64 bits; every (n+6)/2 symbols growing by 5/4
 * up to 8(n+6)), halving the counts when their total passes 2^13 / 2^15.
 * The integer compressor codes the difference between a value and its
 * prediction as k (the number of bits of its magnitude, a symbol of its own
 * model per context) and then the value within the k-bit interval: for
 * k = 0 one bit; for k <= 8 a symbol of 2^k; above, the top 8 bits as a
 * symbol and the k - 8 low bits raw.
 *
 * Invariants the decoder keeps on any input, valid or not: every symbol it
 * returns is below its model's size (the search is a bisection over the
 * distribution, never a table indexed by the input), no operation divides
 * by zero (the length is at least 2^24 before each operation and at least
 * 2^24 >> 16 after the largest raw read), and past the end of its bytes it
 * reads zeros and counts them in `over`: the caller turns a positive count
 * into an error, since a valid stream never reads past its own end.
 */
#ifndef HD_LAZCODER_H
#define HD_LAZCODER_H

#include "base/base.h"

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#define HD__AC_MIN 0x01000000u
#define HD__BM_SHIFT 13
#define HD__BM_MAX (1u << 13)
#define HD__DM_SHIFT 15
#define HD__DM_MAX (1u << 15)

typedef struct hd__bitmodel {
    uint32_t p0, c0, count, cycle, until;
} hd__bitmodel_t;

/* A symbol model of n <= 256 symbols (LASzip's largest are 256; the GPS
 * time model has 516 and is only ever decoded, through the same code). */
typedef struct hd__symmodel {
    uint32_t n, total, cycle, until;
    uint32_t *dist;  /* n entries: cumulative, scaled to 2^15 */
    uint32_t *count; /* n entries */
    /* n > 16: table[t] = the last symbol whose dist >> tshift is below t,
     * for t in [0, tsize + 1] (FastAC's decoder table; a speed-up that
     * gives the symbol the bisection gives) */
    uint32_t *table, tshift, tsize;
    int ready; /* initialised (an integer coder's models are initialised
                  at their first use: most of its 2^k corrector models are
                  never used, and initialising one costs a pass over its
                  symbols, which dominated small chunks) */
} hd__symmodel_t;

void hd__bitmodel_init(hd__bitmodel_t *m);
void hd__bitmodel_update(hd__bitmodel_t *m);
/* Allocate (n symbols, 2 <= n <= 2048) and initialise: HD_OK or HD_ENOMEM. */
int hd__symmodel_new(hd__symmodel_t *m, uint32_t n);
void hd__symmodel_init(hd__symmodel_t *m);
void hd__symmodel_update(hd__symmodel_t *m);
void hd__symmodel_free(hd__symmodel_t *m);
/* Free the models created on first use in slots[0..n) (NULL: never used),
 * and their memory. */
void hd__lazy_models_free(hd__symmodel_t **slots, size_t n);

/* ---- decoder ------------------------------------------------------------ */
typedef struct hd__dec {
    const unsigned char *p, *end;
    uint32_t value, length;
    size_t over; /* bytes read past end (as zeros) */
} hd__dec_t;

HD__INLINE uint32_t hd__dec_byte(hd__dec_t *d) {
    if (d->p < d->end) return *d->p++;
    d->over++;
    return 0;
}
HD__INLINE void hd__dec_init(hd__dec_t *d, const unsigned char *p, size_t n) {
    d->p = p;
    d->end = p + n;
    d->over = 0;
    d->length = 0xFFFFFFFFu;
    d->value = hd__dec_byte(d) << 24;
    d->value |= hd__dec_byte(d) << 16;
    d->value |= hd__dec_byte(d) << 8;
    d->value |= hd__dec_byte(d);
}
HD__INLINE void hd__dec_renorm(hd__dec_t *d) {
    do {
        d->value = d->value << 8 | hd__dec_byte(d);
    } while ((d->length <<= 8) < HD__AC_MIN);
}
HD__INLINE uint32_t hd__dec_bit(hd__dec_t *d, hd__bitmodel_t *m) {
    uint32_t x = m->p0 * (d->length >> HD__BM_SHIFT), sym = d->value >= x;
    if (sym == 0) {
        d->length = x;
        m->c0++;
    } else {
        d->value -= x;
        d->length -= x;
    }
    if (d->length < HD__AC_MIN) hd__dec_renorm(d);
    if (--m->until == 0) hd__bitmodel_update(m);
    return sym;
}
HD__INLINE uint32_t hd__dec_symbol(hd__dec_t *d, hd__symmodel_t *m) {
    uint32_t y = d->length, x = 0, sym = 0, n = m->n;
    uint32_t len = d->length >> HD__DM_SHIFT;
    /* the largest sym with dist[sym] * len <= value, i.e. dist[sym] <=
     * floor(value / len) */
    if (m->table) {
        uint32_t dv = d->value / len, t = dv >> m->tshift;
        if (t > m->tsize) t = m->tsize; /* only when value >= length: bad input */
        sym = m->table[t];
        n = m->table[t + 1] + 1;
        while (n > sym + 1) {
            uint32_t k = (sym + n) >> 1;
            if (m->dist[k] > dv) n = k;
            else sym = k;
        }
        x = m->dist[sym] * len;
        if (sym != m->n - 1) y = m->dist[sym + 1] * len;
    } else {
        uint32_t k = n >> 1;
        do {
            uint32_t z = len * m->dist[k];
            if (z > d->value) {
                n = k;
                y = z;
            } else {
                sym = k;
                x = z;
            }
        } while ((k = (sym + n) >> 1) != sym);
    }
    d->value -= x;
    d->length = y - x;
    if (d->length < HD__AC_MIN) hd__dec_renorm(d);
    m->count[sym]++;
    if (--m->until == 0) hd__symmodel_update(m);
    return sym;
}
/* `bits` raw bits, 1 <= bits <= 19. */
HD__INLINE uint32_t hd__dec_raw19(hd__dec_t *d, unsigned bits) {
    uint32_t sym = d->value / (d->length >>= bits);
    d->value -= d->length * sym;
    if (d->length < HD__AC_MIN) hd__dec_renorm(d);
    return sym;
}
/* `bits` raw bits, 1 <= bits <= 32: above 19, the low 16 first. */
HD__INLINE uint32_t hd__dec_raw(hd__dec_t *d, unsigned bits) {
    if (bits > 19) {
        uint32_t lo = hd__dec_raw19(d, 16);
        return hd__dec_raw19(d, bits - 16) << 16 | lo;
    }
    return hd__dec_raw19(d, bits);
}

/* ---- integer compressor -------------------------------------------------- */
typedef struct hd__intcoder {
    uint32_t bits, contexts, corr_bits, corr_range;
    int32_t corr_min, corr_max;
    uint32_t k; /* k of the last value coded */
    hd__symmodel_t *mbits;  /* contexts models of corr_bits+1 symbols */
    hd__bitmodel_t corr0;
    hd__symmodel_t corr[33]; /* 1..corr_bits: 2^min(k, 8) symbols */
} hd__intcoder_t;

/* bits: 1 to 32 (LAZ uses 8, 16, 32); HD_OK or HD_ENOMEM. */
int hd__intcoder_new(hd__intcoder_t *ic, uint32_t bits, uint32_t contexts);
void hd__intcoder_free(hd__intcoder_t *ic);
/* Free the n integer coders whose addresses are in ic. */
void hd__intcoders_free(hd__intcoder_t *const *ic, size_t n);

/* ---- a set of models, as a list of its fields ---------------------------
 * An item's coder keeps its models as fields of a struct (a "set"); one
 * list of those fields, in the order LASzip's coder creates them, makes
 * them (hd__models_new) and frees them (hd__models_free).  An entry is a
 * field's offset, whether it is an integer coder, how many lie in a row
 * (an array field), and a symbol model's symbols or an integer coder's bits
 * and contexts. */
typedef struct hd__model_spec {
    size_t at;
    unsigned char ic, count;
    uint32_t n, ctx;
} hd__model_spec_t;
#define HD__SYMS(T, field, count, n) {offsetof(T, field), 0, (count), (n), 0}
#define HD__SYM(T, field, n) HD__SYMS(T, field, 1, n)
#define HD__IC(T, field, bits, contexts) {offsetof(T, field), 1, 1, (bits), (contexts)}
/* The models of list[0..n) in the set at `set`, in order: HD_OK, or
 * HD_ENOMEM at the first that cannot be made (those before it are made). */
int hd__models_new(void *set, const hd__model_spec_t *list, size_t n);
/* Free the models of list[0..n) in the set at `set`, each made or zeroed
 * (a freed model is zeroed again, so a field in two lists is harmless). */
void hd__models_free(void *set, const hd__model_spec_t *list, size_t n);
#define HD__MODELS_NEW(set, list) hd__models_new(set, list, sizeof(list) / sizeof *(list))
#define HD__MODELS_FREE(set, list) hd__models_free(set, list, sizeof(list) / sizeof *(list))

/* The model m, initialised at its first use. */
HD__INLINE hd__symmodel_t *hd__ic_model(hd__symmodel_t *m) {
    if (!m->ready) hd__symmodel_init(m);
    return m;
}

HD__INLINE int32_t hd__ic_decode(hd__intcoder_t *ic, hd__dec_t *d, int32_t pred, uint32_t ctx) {
    uint32_t k = ic->k = hd__dec_symbol(d, hd__ic_model(&ic->mbits[ctx]));
    int64_t c;
    if (k) {
        uint32_t v;
        if (k <= 8) {
            v = hd__dec_symbol(d, hd__ic_model(&ic->corr[k]));
        } else {
            unsigned k1 = k - 8;
            v = hd__dec_symbol(d, hd__ic_model(&ic->corr[k]));
            v = v << k1 | hd__dec_raw(d, k1);
        }
        c = (int64_t)v >= ((int64_t)1 << (k - 1)) ? (int64_t)v + 1 : (int64_t)v - (((int64_t)1 << k) - 1);
    } else {
        c = hd__dec_bit(d, &ic->corr0);
    }
    /* pred + c modulo 2^32, then folded into [0, corr_range) when the
     * range is smaller */
    uint32_t real = (uint32_t)pred + (uint32_t)c;
    if (ic->corr_range) {
        int32_t r = (int32_t)real;
        if (r < 0) r += (int32_t)ic->corr_range;
        else if ((uint32_t)r >= ic->corr_range) r -= (int32_t)ic->corr_range;
        return r;
    }
    return (int32_t)real;
}

/* ---- encoder (the mirror of the decoder) ---------------------------------
 * An interval [base, base + length) of 32 bits, a byte shifted out whenever
 * length < 2^24, a carry propagated back through the bytes already
 * written; done() leaves one or two final bytes and pads with zeros to
 * four, so that a decoder, which reads four bytes ahead, consumes the
 * stream exactly.  Output grows in memory; a failed allocation sets `oom`
 * and the rest is not stored (the caller checks oom once at the end). */
typedef struct hd__enc {
    unsigned char *buf;
    size_t size, cap;
    uint32_t base, length;
    int oom;
} hd__enc_t;

void hd__enc_init(hd__enc_t *e);   /* empty, no memory yet */
void hd__enc_reset(hd__enc_t *e);  /* a new stream, keeping the memory */
void hd__enc_free(hd__enc_t *e);
/* Append n raw bytes to e's buffer (nothing, with e's oom flag set, when
 * it cannot grow). */
void hd__enc_put(hd__enc_t *e, const void *p, size_t n);
void hd__enc_bit(hd__enc_t *e, hd__bitmodel_t *m, uint32_t sym);
void hd__enc_symbol(hd__enc_t *e, hd__symmodel_t *m, uint32_t sym);
/* `bits` raw bits of sym, 1 <= bits <= 32. */
void hd__enc_raw(hd__enc_t *e, unsigned bits, uint32_t sym);
void hd__enc_done(hd__enc_t *e);
/* The integer compressor: real given its prediction, in context ctx. */
void hd__ic_encode(hd__intcoder_t *ic, hd__enc_t *e, int32_t pred, int32_t real, uint32_t ctx);

/* ---- facts shared by the POINT10 and POINT14 schemes -------------------- */
/* LASzip's streaming median of the last five values: v[2]; the update rule
 * is part of the format. */
typedef struct hd__median5 {
    int32_t v[5];
    int high;
} hd__median5_t;
void hd__median5_init(hd__median5_t *m);
void hd__median5_add(hd__median5_t *m, int32_t x);
/* The return context m of return r of n: number_return_map (POINT10, 8x8)
 * and number_return_map_6ctx (POINT14, 16x16), indexed [n][r]. */
extern const unsigned char hd__laz_rmap10[8][8];
extern const unsigned char hd__laz_rmap14[16][16];
/* The return level l: |n - r|, capped at 7. */
HD__INLINE unsigned hd__laz_level(unsigned n, unsigned r) {
    unsigned l = n > r ? n - r : r - n;
    return l > 7 ? 7 : l;
}
/* The context of dy from dx's k (cap 20), of z from the mean k (cap 18). */
HD__INLINE unsigned hd__laz_kctx(unsigned k, unsigned cap) { return k < cap ? (k & ~1u) : cap; }

/* ---- the models of pointwise LAZ's items ---------------------------------
 * POINT10, GPSTIME11 and RGB12 in version 1 or 2, one set for the reader
 * (laz.c) and the pointwise encoder (write_lazpw.c).  Each hd__pw_*_new
 * creates one item's models (HD_OK or HD_ENOMEM) in m zeroed first;
 * hd__pw_models_free frees whatever was created, after a failure too. */
typedef struct hd__pw_models {
    /* POINT10 */
    hd__symmodel_t changed, scan[2];                     /* scan: v2 only */
    hd__symmodel_t *bitbyte[256], *cls[256], *user[256]; /* created at first use */
    hd__intcoder_t intensity, psid, dx, dy, dz, scan1;   /* scan1: v1 only */
    hd__median5_t mx[16], my[16];                        /* v2 */
    /* GPSTIME11 */
    hd__symmodel_t gmulti, gzero;
    hd__intcoder_t gic;
    /* RGB12 */
    hd__symmodel_t used, cdiff[6]; /* cdiff: v2 */
    hd__intcoder_t cic;            /* v1 */
} hd__pw_models_t;
int hd__pw_point10_new(hd__pw_models_t *m, int v2);
int hd__pw_gps11_new(hd__pw_models_t *m, int v2);
int hd__pw_rgb12_new(hd__pw_models_t *m, int v2);
void hd__pw_models_free(hd__pw_models_t *m);

#endif
