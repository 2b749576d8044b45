/*
 * laz14.h -- every field of layered LAZ (LAS 1.4 point formats 6-10,
 * LASzip compressor 3), decoded to whole records and encoded from them
 * (laz14.c).  The reader's ordinary path (laz.c) decodes x, y and z alone;
 * these serve the writers, which re-encode a subset of the points.
 */
#ifndef HD_LAZ14_H
#define HD_LAZ14_H

#include "lazcoder.h"

#include <stddef.h>

/* The items of a layered file, as its LASzip VLR lists them: POINT14
 * first, then RGB14 or RGBNIR14, WAVEPACKET14, BYTE14, versions 3 or 4. */
typedef struct hd__laz14_items {
    unsigned n, type[32], size[32], version[32];
} hd__laz14_items_t;

enum { HD__LAZ_IT_POINT14 = 10, HD__LAZ_IT_RGB14 = 11, HD__LAZ_IT_RGBNIR14 = 12, HD__LAZ_IT_WAVE14 = 13,
       HD__LAZ_IT_BYTE14 = 14 };

/* The models of POINT14's return numbers and x, y, z in one scanner
 * channel (with the medians of the last five dx, dy): the ones the
 * reader's ordinary path (laz.c) decodes, and part of the ones the
 * layered codec (laz14.c) codes.  nret and rnum are created at their first
 * use.  hd__p14_models_new: HD_OK or HD_ENOMEM; hd__p14_models_free frees
 * them after a failure too (m zeroed before the first call). */
typedef struct hd__p14_models {
    hd__symmodel_t changed[8], scanner, rn_same;
    hd__symmodel_t *nret[16], *rnum[16];
    hd__intcoder_t dx, dy, dz;
    hd__median5_t mx[12], my[12];
} hd__p14_models_t;
int hd__p14_models_new(hd__p14_models_t *m);
void hd__p14_models_free(hd__p14_models_t *m);

/* The n records (rec bytes each) of the layered chunk b[0..nb) into recs.
 * HD_OK, or HD_EFORMAT / HD_ENOMEM with msg and *at (the byte offset in
 * the chunk the problem is at). */
int hd__laz14_decode(const unsigned char *b, size_t nb, size_t n, size_t rec, const hd__laz14_items_t *it,
                     unsigned char *recs, char *msg, size_t len, size_t *at);

/* The chunk of the n records (rec bytes each) after its raw first record:
 * its point count, its layer sizes and its layers, into out (reset
 * first).  HD_OK, HD_ENOMEM, or HD_EINVAL when a record would not decode
 * back to itself (a defect of the coder, checked on every point). */
int hd__laz14_encode(const unsigned char *recs, size_t n, size_t rec, const hd__laz14_items_t *it, hd__enc_t *out);

#endif
