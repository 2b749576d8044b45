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

int hd__symmodel_new(hd__symmodel_t *m, uint32_t n) {
    assert(n >= 2 && n <= 2048);
    m->n = n;
    m->dist = hd__malloc_array(2 * (size_t)n, sizeof(uint32_t));
    if (!m->dist) return HD_ENOMEM;
    m->count = m->dist + n;
    hd__symmodel_init(m);
    return HD_OK;
}

void hd__symmodel_init(hd__symmodel_t *m) {
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
    uint32_t scale = 0x80000000u / m->total, sum = 0;
    for (uint32_t k = 0; k < m->n; k++) {
        m->dist[k] = (scale * sum) >> (31 - HD__DM_SHIFT);
        sum += m->count[k];
    }
    m->cycle = (5 * m->cycle) >> 2;
    uint32_t max = (m->n + 6) << 3;
    if (m->cycle > max) m->cycle = max;
    m->until = m->cycle;
}

void hd__symmodel_free(hd__symmodel_t *m) {
    free(m->dist);
    m->dist = m->count = NULL;
}

int hd__intcoder_new(hd__intcoder_t *ic, uint32_t bits, uint32_t contexts) {
    assert(bits == 16 || bits == 32);
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
        if (hd__symmodel_new(&ic->mbits[i], ic->corr_bits + 1)) goto fail;
    hd__bitmodel_init(&ic->corr0);
    for (uint32_t i = 1; i <= ic->corr_bits; i++)
        if (hd__symmodel_new(&ic->corr[i], 1u << (i <= 8 ? i : 8))) goto fail;
    return HD_OK;
fail:
    hd__intcoder_free(ic);
    return HD_ENOMEM;
}

void hd__intcoder_init(hd__intcoder_t *ic) {
    for (uint32_t i = 0; i < ic->contexts; i++) hd__symmodel_init(&ic->mbits[i]);
    hd__bitmodel_init(&ic->corr0);
    for (uint32_t i = 1; i <= ic->corr_bits; i++) hd__symmodel_init(&ic->corr[i]);
    ic->k = 0;
}

void hd__intcoder_free(hd__intcoder_t *ic) {
    if (ic->mbits)
        for (uint32_t i = 0; i < ic->contexts; i++) hd__symmodel_free(&ic->mbits[i]);
    free(ic->mbits);
    ic->mbits = NULL;
    for (uint32_t i = 1; i <= 32; i++) hd__symmodel_free(&ic->corr[i]);
}
