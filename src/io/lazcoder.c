/*
 * lazcoder.c -- the adaptive models and the integer compressor of LASzip's
 * range coder (lazcoder.h has the format's facts).  A model's state is a
 * pure function of the symbols coded with it, so an encoder and a decoder
 * that code the same symbols hold the same distributions at every step:
 * that is the whole contract, and the update rules below are the format.
 *
 * Symbol model update: the running total grows by the symbols seen since
 * the last update (the first time: one per symbol, the initial counts);
 * past 2^15 every count is halved, rounding up, and the total recomputed;
 * then dist[k] = (floor(2^31 / total) * sum_{j<k} count[j]) >> 16, each
 * product modulo 2^32 as the format computes it.  Bit model: the same with
 * 2^13 and p0 = (c0 * floor(2^31 / count)) >> 18.
 */
#include "lazcoder.h"

#include <assert.h>
#include <stdlib.h>

void hd__bitmodel_init(hd__bitmodel_t *m) {
    m->c0 = 1;
    m->count = 2;
    m->p0 = 1u << (HD__BM_SHIFT - 1);
    m->cycle = m->until = 4;
}

void hd__bitmodel_update(hd__bitmodel_t *m) {
    if ((m->count += m->cycle) > HD__BM_MAX) {
        m->count = (m->count + 1) >> 1;
        m->c0 = (m->c0 + 1) >> 1;
        if (m->c0 == m->count) m->count++;
    }
    uint32_t scale = 0x80000000u / m->count;
    m->p0 = (m->c0 * scale) >> (31 - HD__BM_SHIFT);
    m->cycle = (5 * m->cycle) >> 2;
    if (m->cycle > 64) m->cycle = 64;
    m->until = m->cycle;
}

/* Allocate a model of n symbols, not initialised (ready = 0). */
static int symmodel_alloc(hd__symmodel_t *m, uint32_t n) {
    assert(n >= 2 && n <= 2048);
    m->n = n;
    m->tsize = m->tshift = 0;
    if (n > 16) {
        uint32_t bits = 3;
        while (n > (1u << (bits + 2))) bits++;
        m->tsize = 1u << bits;
        m->tshift = HD__DM_SHIFT - bits;
    }
    m->dist = hd__malloc_array(2 * (size_t)n + (m->tsize ? m->tsize + 2 : 0), sizeof(uint32_t));
    if (!m->dist) return HD_ENOMEM;
    m->count = m->dist + n;
    m->table = m->tsize ? m->dist + 2 * n : NULL;
    m->ready = 0;
    return HD_OK;
}

int hd__symmodel_new(hd__symmodel_t *m, uint32_t n) {
    int rc = symmodel_alloc(m, n);
    if (rc == HD_OK) hd__symmodel_init(m);
    return rc;
}

void hd__symmodel_init(hd__symmodel_t *m) {
    m->ready = 1;
    m->total = 0;
    m->cycle = m->n;
    for (uint32_t k = 0; k < m->n; k++) m->count[k] = 1;
    hd__symmodel_update(m);
    m->until = m->cycle = (m->n + 6) >> 1;
}

void hd__symmodel_update(hd__symmodel_t *m) {
    if ((m->total += m->cycle) > HD__DM_MAX) {
        m->total = 0;
        for (uint32_t k = 0; k < m->n; k++) m->total += (m->count[k] = (m->count[k] + 1) >> 1);
    }
    uint32_t scale = 0x80000000u / m->total, sum = 0, s = 0;
    for (uint32_t k = 0; k < m->n; k++) {
        m->dist[k] = (scale * sum) >> (31 - HD__DM_SHIFT);
        sum += m->count[k];
        if (m->table) {
            uint32_t w = m->dist[k] >> m->tshift;
            while (s < w) m->table[++s] = k - 1;
        }
    }
    if (m->table) {
        m->table[0] = 0;
        while (s <= m->tsize) m->table[++s] = m->n - 1;
    }
    m->cycle = (5 * m->cycle) >> 2;
    uint32_t max = (m->n + 6) << 3;
    if (m->cycle > max) m->cycle = max;
    m->until = m->cycle;
}

void hd__symmodel_free(hd__symmodel_t *m) {
    free(m->dist);
    m->dist = m->count = m->table = NULL;
}

void hd__lazy_models_free(hd__symmodel_t **slots, size_t n) {
    for (size_t i = 0; i < n; i++)
        if (slots[i]) {
            hd__symmodel_free(slots[i]);
            free(slots[i]);
            slots[i] = NULL;
        }
}

int hd__intcoder_new(hd__intcoder_t *ic, uint32_t bits, uint32_t contexts) {
    assert(bits >= 1 && bits <= 32);
    memset(ic, 0, sizeof *ic);
    ic->bits = bits;
    ic->contexts = contexts;
    if (bits < 32) {
        ic->corr_bits = bits;
        ic->corr_range = 1u << bits;
        ic->corr_min = -(int32_t)(ic->corr_range / 2);
        ic->corr_max = ic->corr_min + (int32_t)ic->corr_range - 1;
    } else {
        ic->corr_bits = 32;
        ic->corr_range = 0;
        ic->corr_min = INT32_MIN;
        ic->corr_max = INT32_MAX;
    }
    ic->mbits = calloc(contexts, sizeof *ic->mbits);
    if (!ic->mbits) return HD_ENOMEM;
    for (uint32_t i = 0; i < contexts; i++)
        if (symmodel_alloc(&ic->mbits[i], ic->corr_bits + 1)) goto fail;
    hd__bitmodel_init(&ic->corr0);
    for (uint32_t i = 1; i <= ic->corr_bits; i++)
        if (symmodel_alloc(&ic->corr[i], 1u << (i <= 8 ? i : 8))) goto fail;
    return HD_OK;
fail:
    hd__intcoder_free(ic);
    return HD_ENOMEM;
}

void hd__intcoder_free(hd__intcoder_t *ic) {
    if (ic->mbits)
        for (uint32_t i = 0; i < ic->contexts; i++) hd__symmodel_free(&ic->mbits[i]);
    free(ic->mbits);
    ic->mbits = NULL;
    for (uint32_t i = 1; i <= 32; i++) hd__symmodel_free(&ic->corr[i]);
}

void hd__intcoders_free(hd__intcoder_t *const *ic, size_t n) {
    for (size_t i = 0; i < n; i++) hd__intcoder_free(ic[i]);
}

int hd__models_new(void *set, const hd__model_spec_t *list, size_t n) {
    for (size_t i = 0; i < n; i++)
        for (unsigned k = 0; k < list[i].count; k++) {
            char *at = (char *)set + list[i].at;
            int rc = list[i].ic ? hd__intcoder_new((hd__intcoder_t *)(void *)at + k, list[i].n, list[i].ctx)
                                : hd__symmodel_new((hd__symmodel_t *)(void *)at + k, list[i].n);
            if (rc) return rc;
        }
    return HD_OK;
}

void hd__models_free(void *set, const hd__model_spec_t *list, size_t n) {
    for (size_t i = 0; i < n; i++)
        for (unsigned k = 0; k < list[i].count; k++) {
            char *at = (char *)set + list[i].at;
            if (list[i].ic) hd__intcoder_free((hd__intcoder_t *)(void *)at + k);
            else hd__symmodel_free((hd__symmodel_t *)(void *)at + k);
        }
}

void hd__median5_init(hd__median5_t *m) {
    memset(m->v, 0, sizeof m->v);
    m->high = 1;
}
/* LASzip's streaming median: v[2] approximates the median of the last
 * five values; the update rule is part of the format. */
void hd__median5_add(hd__median5_t *m, int32_t x) {
    int32_t *v = m->v;
    if (m->high) {
        if (x < v[2]) {
            v[4] = v[3];
            v[3] = v[2];
            if (x < v[0]) {
                v[2] = v[1];
                v[1] = v[0];
                v[0] = x;
            } else if (x < v[1]) {
                v[2] = v[1];
                v[1] = x;
            } else {
                v[2] = x;
            }
        } else {
            if (x < v[3]) {
                v[4] = v[3];
                v[3] = x;
            } else {
                v[4] = x;
            }
            m->high = 0;
        }
    } else {
        if (v[2] < x) {
            v[0] = v[1];
            v[1] = v[2];
            if (v[4] < x) {
                v[2] = v[3];
                v[3] = v[4];
                v[4] = x;
            } else if (v[3] < x) {
                v[2] = v[3];
                v[3] = x;
            } else {
                v[2] = x;
            }
        } else {
            if (v[1] < x) {
                v[0] = v[1];
                v[1] = x;
            } else {
                v[0] = x;
            }
            m->high = 1;
        }
    }
}

/* number_return_map (POINT10): the return context m of return r of n. */
const unsigned char hd__laz_rmap10[8][8] = {
    {15, 14, 13, 12, 11, 10, 9, 8}, {14, 0, 1, 3, 6, 10, 10, 9},   {13, 1, 2, 4, 7, 11, 11, 10},
    {12, 3, 4, 5, 8, 12, 12, 11},   {11, 6, 7, 8, 9, 13, 13, 12},  {10, 10, 11, 12, 13, 14, 14, 13},
    {9, 10, 11, 12, 13, 14, 15, 14}, {8, 9, 10, 11, 12, 13, 14, 15}};
/* number_return_map_6ctx (POINT14). */
const unsigned char hd__laz_rmap14[16][16] = {
    {0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5}, {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
    {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3}, {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
    {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};

/* ---- encoder ------------------------------------------------------------- */
void hd__enc_init(hd__enc_t *e) {
    memset(e, 0, sizeof *e);
    e->length = 0xFFFFFFFFu;
}
void hd__enc_reset(hd__enc_t *e) {
    e->size = 0;
    e->base = 0;
    e->length = 0xFFFFFFFFu;
}
void hd__enc_free(hd__enc_t *e) {
    free(e->buf);
    e->buf = NULL;
    e->size = e->cap = 0;
}
/* Room for n more bytes in e's buffer (doubled as needed): 0, or -1 with
 * e's oom flag set. */
static int enc_room(hd__enc_t *e, size_t n) {
    if (n <= e->cap - e->size) return 0;
    size_t cap = e->cap ? e->cap : 4096;
    while (cap - e->size < n && cap <= SIZE_MAX / 2) cap *= 2;
    unsigned char *p = cap - e->size >= n ? realloc(e->buf, cap) : NULL;
    if (!p) {
        e->oom = 1;
        return -1;
    }
    e->buf = p;
    e->cap = cap;
    return 0;
}
void hd__enc_put(hd__enc_t *e, const void *p, size_t n) {
    if (n == 0 || enc_room(e, n)) return;
    memcpy(e->buf + e->size, p, n);
    e->size += n;
}
static void enc_byte(hd__enc_t *e, unsigned char b) {
    if (e->size == e->cap && enc_room(e, 1)) return;
    e->buf[e->size++] = b;
}
static void enc_carry(hd__enc_t *e) {
    size_t i = e->size;
    while (i > 0 && e->buf[i - 1] == 0xFF) e->buf[--i] = 0;
    if (i > 0) e->buf[i - 1]++; /* i = 0 only after a failed allocation */
}
static void enc_renorm(hd__enc_t *e) {
    do {
        enc_byte(e, (unsigned char)(e->base >> 24));
        e->base <<= 8;
    } while ((e->length <<= 8) < HD__AC_MIN);
}
void hd__enc_bit(hd__enc_t *e, hd__bitmodel_t *m, uint32_t sym) {
    uint32_t x = m->p0 * (e->length >> HD__BM_SHIFT);
    if (sym == 0) {
        e->length = x;
        m->c0++;
    } else {
        uint32_t b = e->base;
        e->base += x;
        e->length -= x;
        if (b > e->base) enc_carry(e);
    }
    if (e->length < HD__AC_MIN) enc_renorm(e);
    if (--m->until == 0) hd__bitmodel_update(m);
}
void hd__enc_symbol(hd__enc_t *e, hd__symmodel_t *m, uint32_t sym) {
    assert(sym < m->n);
    uint32_t x, b = e->base;
    if (sym == m->n - 1) {
        x = m->dist[sym] * (e->length >> HD__DM_SHIFT);
        e->base += x;
        e->length -= x;
    } else {
        x = m->dist[sym] * (e->length >>= HD__DM_SHIFT);
        e->base += x;
        e->length = m->dist[sym + 1] * e->length - x;
    }
    if (b > e->base) enc_carry(e);
    if (e->length < HD__AC_MIN) enc_renorm(e);
    m->count[sym]++;
    if (--m->until == 0) hd__symmodel_update(m);
}
void hd__enc_raw(hd__enc_t *e, unsigned bits, uint32_t sym) {
    if (bits > 19) {
        hd__enc_raw(e, 16, sym & 0xFFFF);
        sym >>= 16;
        bits -= 16;
    }
    uint32_t b = e->base;
    e->base += sym * (e->length >>= bits);
    if (b > e->base) enc_carry(e);
    if (e->length < HD__AC_MIN) enc_renorm(e);
}
void hd__enc_done(hd__enc_t *e) {
    uint32_t b = e->base;
    int another = 1;
    if (e->length > 2 * HD__AC_MIN) {
        e->base += HD__AC_MIN;
        e->length = HD__AC_MIN >> 1;
    } else {
        e->base += HD__AC_MIN >> 1;
        e->length = HD__AC_MIN >> 9;
        another = 0;
    }
    if (b > e->base) enc_carry(e);
    enc_renorm(e);
    enc_byte(e, 0);
    enc_byte(e, 0);
    if (another) enc_byte(e, 0);
}

void hd__ic_encode(hd__intcoder_t *ic, hd__enc_t *e, int32_t pred, int32_t real, uint32_t ctx) {
    int64_t c = (int32_t)((uint32_t)real - (uint32_t)pred);
    if (ic->corr_range) {
        if (c < ic->corr_min) c += ic->corr_range;
        else if (c > ic->corr_max) c -= ic->corr_range;
    }
    int64_t c1 = c <= 0 ? -c : c - 1;
    uint32_t k = 0;
    while (c1) {
        c1 >>= 1;
        k++;
    }
    ic->k = k;
    hd__enc_symbol(e, hd__ic_model(&ic->mbits[ctx]), k);
    if (k) {
        c = c < 0 ? c + (((int64_t)1 << k) - 1) : c - 1;
        if (k <= 8) {
            hd__enc_symbol(e, hd__ic_model(&ic->corr[k]), (uint32_t)c);
        } else {
            unsigned k1 = k - 8;
            hd__enc_symbol(e, hd__ic_model(&ic->corr[k]), (uint32_t)(c >> k1));
            hd__enc_raw(e, k1, (uint32_t)(c & (((int64_t)1 << k1) - 1)));
        }
    } else {
        hd__enc_bit(e, &ic->corr0, (uint32_t)c);
    }
}

/* ---- the models of pointwise LAZ's items --------------------------------- */
/* Each item's models in version 2 and in version 1 (hd__model_spec_t). */
typedef hd__pw_models_t pw_t;
static const hd__model_spec_t point10_v2[] = {
    HD__SYM(pw_t, changed, 64), HD__SYMS(pw_t, scan, 2, 256), HD__IC(pw_t, intensity, 16, 4), HD__IC(pw_t, dx, 32, 2),
    HD__IC(pw_t, dy, 32, 22),   HD__IC(pw_t, psid, 16, 1),    HD__IC(pw_t, dz, 32, 20)};
static const hd__model_spec_t point10_v1[] = {
    HD__SYM(pw_t, changed, 64), HD__IC(pw_t, scan1, 8, 2), HD__IC(pw_t, intensity, 16, 1), HD__IC(pw_t, dx, 32, 1),
    HD__IC(pw_t, dy, 32, 20),   HD__IC(pw_t, psid, 16, 1), HD__IC(pw_t, dz, 32, 20)};
static const hd__model_spec_t gps11_v2[] = {
    HD__SYM(pw_t, gmulti, 516), HD__SYM(pw_t, gzero, 6), HD__IC(pw_t, gic, 32, 9)};
static const hd__model_spec_t gps11_v1[] = {
    HD__SYM(pw_t, gmulti, 512), HD__SYM(pw_t, gzero, 3), HD__IC(pw_t, gic, 32, 6)};
static const hd__model_spec_t rgb12_v2[] = {HD__SYM(pw_t, used, 128), HD__SYMS(pw_t, cdiff, 6, 256)};
static const hd__model_spec_t rgb12_v1[] = {HD__SYM(pw_t, used, 64), HD__IC(pw_t, cic, 8, 6)};

int hd__pw_point10_new(hd__pw_models_t *m, int v2) {
    for (int i = 0; i < 16; i++) {
        hd__median5_init(&m->mx[i]);
        hd__median5_init(&m->my[i]);
    }
    return v2 ? HD__MODELS_NEW(m, point10_v2) : HD__MODELS_NEW(m, point10_v1);
}

int hd__pw_gps11_new(hd__pw_models_t *m, int v2) {
    return v2 ? HD__MODELS_NEW(m, gps11_v2) : HD__MODELS_NEW(m, gps11_v1);
}

int hd__pw_rgb12_new(hd__pw_models_t *m, int v2) {
    return v2 ? HD__MODELS_NEW(m, rgb12_v2) : HD__MODELS_NEW(m, rgb12_v1);
}

/* Every field of the set is in one of the lists freed (gps11_v1's are
 * gps11_v2's fields). */
void hd__pw_models_free(hd__pw_models_t *m) {
    HD__MODELS_FREE(m, point10_v2), HD__MODELS_FREE(m, point10_v1);
    HD__MODELS_FREE(m, gps11_v2), HD__MODELS_FREE(m, rgb12_v2), HD__MODELS_FREE(m, rgb12_v1);
    hd__lazy_models_free(m->bitbyte, 256);
    hd__lazy_models_free(m->cls, 256);
    hd__lazy_models_free(m->user, 256);
}
